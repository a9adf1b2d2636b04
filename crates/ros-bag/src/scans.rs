//! The scans of one cloud topic, each posed in a fixed frame by the bag's transforms.

use crate::bag::Bag;
use crate::error::BagError;
use crate::image::{CameraInfo, IMAGE};
use crate::msgs::{Header, TF_MESSAGE, TransformStamped};
use crate::tf::TfTree;
use pointcloud::{Isometry3, PointCloud, SensorPose};

/// The frame [`ScanQuery::trajectory`] poses the clouds in.
pub const TRAJECTORY_FRAME: &str = "trajectory";

/// The `camera_info` topic next to an image topic.
pub fn sibling_camera_info(image_topic: &str) -> String {
    match image_topic.rsplit_once('/') {
        Some((dir, _)) => format!("{dir}/camera_info"),
        None => "camera_info".to_owned(),
    }
}

/// Which clouds [`read_scans`] takes and where it poses them.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanQuery {
    /// The `sensor_msgs/PointCloud2`, `sensor_msgs/LaserScan` or depth `sensor_msgs/Image`
    /// topic.
    pub topic: String,
    /// For a depth image topic: its `sensor_msgs/CameraInfo` topic (`None`: the sibling
    /// `camera_info` of the image topic, `/camera/depth/image_rect` →
    /// `/camera/depth/camera_info`). Each image takes the latest camera info before it in the
    /// bag, or the first one when none came before.
    pub camera_info: Option<String>,
    /// `fixed_from_sensor` samples (stamps in nanoseconds, in order): pose the clouds by
    /// these, interpolated at each cloud's stamp, instead of by `/tf` (a trajectory from
    /// odometry or SLAM for a bag without transforms).
    pub trajectory: Option<Vec<(i64, Isometry3)>>,
    /// Pose the clouds (`false`: leave them in their sensor frame without looking up any
    /// transform, for per-frame work such as terrain classes).
    pub posed: bool,
    /// The frame the scans are posed in (`odom`, `map`); `None`: the root of the first cloud's
    /// transform chain, or, without any transform to it, the sensor frame (no pose).
    pub fixed_frame: Option<String>,
    /// Keep every N-th cloud of the time window (1: all).
    pub every: usize,
    /// Keep a cloud only when its sensor moved at least this far (metres) since the last one
    /// kept; needs poses.
    pub min_motion: Option<f64>,
    /// The time window, in seconds from the bag's first message (log time).
    pub start_s: Option<f64>,
    /// See `start_s`.
    pub end_s: Option<f64>,
}

impl ScanQuery {
    /// Every cloud of `topic`, in the default fixed frame.
    pub fn all(topic: &str) -> ScanQuery {
        ScanQuery {
            topic: topic.to_owned(),
            camera_info: None,
            trajectory: None,
            posed: true,
            fixed_frame: None,
            every: 1,
            min_motion: None,
            start_s: None,
            end_s: None,
        }
    }
}

/// One cloud picked from a bag.
#[derive(Clone, Debug, PartialEq)]
pub struct BagScan {
    /// `header.stamp`, nanoseconds since the epoch.
    pub stamp_ns: i64,
    /// Log time relative to the bag's first message, in seconds.
    pub time_s: f64,
    /// `header.frame_id`.
    pub frame_id: String,
    /// The cloud in its sensor frame; [`PointCloud::sensor_pose`] is `fixed_from_sensor` at the
    /// stamp, or `None` when the scans stay in their sensor frame.
    pub cloud: PointCloud,
}

/// What [`read_scans`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct BagScans {
    /// The scans kept, in bag order.
    pub scans: Vec<BagScan>,
    /// The fixed frame, or `None` if the scans stay in their sensor frame.
    pub fixed_frame: Option<String>,
    /// Clouds of the topic in the bag, in the time window, and kept.
    pub counts: (usize, usize, usize),
    /// Things the caller should tell the user (no transforms, …).
    pub warnings: Vec<String>,
}

/// Reads the clouds of `query.topic`, each posed by the transform from its frame to the fixed
/// frame at its stamp (interpolated between `/tf` samples, see [`TfTree::lookup`]).
///
/// Reads the bag twice: the transforms first, so that a cloud is posed by samples on both sides
/// of its stamp, then the clouds.
///
/// # Errors
/// The bag's errors; [`BagError::Tf`] with the cloud's topic and position when its transform
/// chain is broken or its stamp lies outside the samples; [`BagError::NotABag`] when the topic
/// holds no cloud.
pub fn read_scans(bag: &Bag, query: &ScanQuery) -> Result<BagScans, BagError> {
    let mut scans = Vec::new();
    let summary = for_each_scan(bag, query, |scan| {
        scans.push(scan);
        Ok::<(), BagError>(())
    })?;
    Ok(BagScans {
        scans,
        fixed_frame: summary.fixed_frame,
        counts: summary.counts,
        warnings: summary.warnings,
    })
}

/// What [`for_each_scan`] walked: [`BagScans`] without the scans.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanSummary {
    /// The fixed frame, or `None` if the scans stay in their sensor frame.
    pub fixed_frame: Option<String>,
    /// Clouds of the topic in the bag, in the time window, and kept.
    pub counts: (usize, usize, usize),
    /// Things the caller should tell the user (no transforms, …).
    pub warnings: Vec<String>,
}

/// [`read_scans`] one scan at a time: calls `f` with each scan kept, in bag order, so that a
/// long bag is never in memory at once. Stops at the first error of the bag or of `f`.
///
/// # Errors
/// As [`read_scans`], and whatever `f` returns.
pub fn for_each_scan<E: From<BagError>>(
    bag: &Bag,
    query: &ScanQuery,
    mut f: impl FnMut(BagScan) -> Result<(), E>,
) -> Result<ScanSummary, E> {
    let mut tree = TfTree::new();
    let mut start_ns = u64::MAX;
    let mut any_tf = false;
    let mut first_frame: Option<String> = None;
    let info_topic = query.camera_info.clone().unwrap_or_else(|| sibling_camera_info(&query.topic));
    let mut first_info: Option<CameraInfo> = None;
    let mut is_image = false;
    bag.for_each_message(|m| {
        start_ns = start_ns.min(m.log_time_ns);
        if m.type_name == TF_MESSAGE && query.trajectory.is_none() {
            tree.insert(&m.transforms()?, m.topic == "/tf_static");
            any_tf = true;
        } else if m.topic == query.topic && first_frame.is_none() {
            first_frame = m.header()?.map(|h| h.frame_id);
            is_image = m.type_name == IMAGE;
        } else if m.topic == info_topic && first_info.is_none() && m.type_name != IMAGE {
            first_info = Some(m.camera_info()?);
        }
        Ok(())
    })?;
    let Some(first_frame) = first_frame else {
        return Err(E::from(BagError::NotABag {
            path: bag.path().to_owned(),
            reason: format!("no message on topic {}", query.topic),
        }));
    };
    if is_image && first_info.is_none() {
        return Err(E::from(BagError::NotABag {
            path: bag.path().to_owned(),
            reason: format!(
                "{} holds images but {info_topic} no sensor_msgs/CameraInfo (give its topic)",
                query.topic
            ),
        }));
    }
    if let Some(samples) = &query.trajectory {
        let transforms: Vec<TransformStamped> = samples
            .iter()
            .map(|&(stamp_ns, pose)| TransformStamped {
                header: Header { stamp_ns, frame_id: TRAJECTORY_FRAME.to_owned() },
                child_frame_id: first_frame.clone(),
                parent_from_child: pose,
            })
            .collect();
        tree.insert(&transforms, false);
    }
    let mut warnings = Vec::new();
    let fixed_frame = match &query.fixed_frame {
        _ if !query.posed => None,
        _ if query.trajectory.is_some() => Some(TRAJECTORY_FRAME.to_owned()),
        Some(f) => Some(f.clone()),
        None => {
            let root = tree.root(&first_frame);
            if root == first_frame {
                warnings.push(format!(
                    "no transform from `{first_frame}`: the scans stay in their sensor frame"
                ));
                None
            } else {
                Some(root)
            }
        }
    };
    if !any_tf && query.fixed_frame.is_some() {
        warnings.push("the bag has no /tf or /tf_static".to_owned());
    }
    let mut kept = 0usize;
    let mut failed: Option<E> = None;
    let (mut on_topic, mut in_window) = (0usize, 0usize);
    let mut last_kept: Option<pointcloud::Point3> = None;
    let mut info = first_info;
    let walked = bag.for_each_message(|m| {
        if is_image && m.topic == info_topic {
            info = Some(m.camera_info()?);
        }
        if m.topic != query.topic {
            return Ok(());
        }
        on_topic += 1;
        let time_s = (m.log_time_ns - start_ns) as f64 * 1e-9;
        if query.start_s.is_some_and(|s| time_s < s) || query.end_s.is_some_and(|e| time_s > e) {
            return Ok(());
        }
        in_window += 1;
        if (in_window - 1) % query.every.max(1) != 0 {
            return Ok(());
        }
        let (header, mut cloud) = match &info {
            Some(info) if is_image => m.depth_cloud(info)?,
            _ => m.cloud()?,
        };
        if let Some(fixed) = &fixed_frame {
            let fixed_from_sensor =
                tree.lookup(fixed, &header.frame_id, header.stamp_ns).map_err(|source| {
                    BagError::Tf {
                        path: m.file.to_owned(),
                        offset: m.offset,
                        topic: m.topic.to_owned(),
                        source: Box::new(source),
                    }
                })?;
            let at = pointcloud::Point3::from(fixed_from_sensor.translation.vector);
            if let (Some(min), Some(last)) = (query.min_motion, last_kept)
                && (at - last).norm() < min
            {
                return Ok(());
            }
            last_kept = Some(at);
            cloud.set_sensor_pose(Some(SensorPose { world_from_sensor: fixed_from_sensor }));
        }
        kept += 1;
        let scan = BagScan { stamp_ns: header.stamp_ns, time_s, frame_id: header.frame_id, cloud };
        f(scan).map_err(|e| {
            failed = Some(e);
            BagError::Stopped
        })
    });
    if let Some(e) = failed {
        return Err(e);
    }
    walked?;
    if query.min_motion.is_some() && fixed_frame.is_none() {
        warnings.push("--min-motion needs poses: every cloud is kept".to_owned());
    }
    Ok(ScanSummary { fixed_frame, counts: (on_topic, in_window, kept), warnings })
}
