//! The scans of one cloud topic, each posed in a fixed frame by the bag's transforms.

use crate::bag::Bag;
use crate::error::BagError;
use crate::msgs::TF_MESSAGE;
use crate::tf::TfTree;
use pointcloud::{PointCloud, SensorPose};

/// Which clouds [`read_scans`] takes and where it poses them.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanQuery {
    /// The `sensor_msgs/PointCloud2` or `sensor_msgs/LaserScan` topic.
    pub topic: String,
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
    let mut tree = TfTree::new();
    let mut start_ns = u64::MAX;
    let mut any_tf = false;
    let mut first_frame: Option<String> = None;
    bag.for_each_message(|m| {
        start_ns = start_ns.min(m.log_time_ns);
        if m.type_name == TF_MESSAGE {
            tree.insert(&m.transforms()?, m.topic == "/tf_static");
            any_tf = true;
        } else if m.topic == query.topic && first_frame.is_none() {
            first_frame = m.header()?.map(|h| h.frame_id);
        }
        Ok(())
    })?;
    let Some(first_frame) = first_frame else {
        return Err(BagError::NotABag {
            path: bag.path().to_owned(),
            reason: format!("no message on topic {}", query.topic),
        });
    };
    let mut warnings = Vec::new();
    let fixed_frame = match &query.fixed_frame {
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
    let mut scans = Vec::new();
    let (mut on_topic, mut in_window) = (0usize, 0usize);
    let mut last_kept: Option<pointcloud::Point3> = None;
    bag.for_each_message(|m| {
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
        let (header, mut cloud) = m.cloud()?;
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
        scans.push(BagScan { stamp_ns: header.stamp_ns, time_s, frame_id: header.frame_id, cloud });
        Ok(())
    })?;
    if query.min_motion.is_some() && fixed_frame.is_none() {
        warnings.push("--min-motion needs poses: every cloud is kept".to_owned());
    }
    let kept = scans.len();
    Ok(BagScans { scans, fixed_frame, counts: (on_topic, in_window, kept), warnings })
}
