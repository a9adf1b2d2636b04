//! What a bag holds: topics, types, counts, time span, frames.

use crate::bag::Bag;
use crate::error::BagError;
use crate::msgs::TF_MESSAGE;
use std::collections::{BTreeMap, BTreeSet};

/// One topic of a bag.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TopicInfo {
    /// The topic.
    pub topic: String,
    /// Its message type (`sensor_msgs/PointCloud2`).
    pub type_name: String,
    /// Its number of messages.
    pub count: u64,
    /// The first and last log time, in nanoseconds since the epoch.
    pub first_ns: u64,
    /// See `first_ns`.
    pub last_ns: u64,
    /// The `header.frame_id`s its messages name (for `tf2_msgs/TFMessage`: parents and
    /// children).
    pub frames: BTreeSet<String>,
}

/// What a bag holds.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct BagInfo {
    /// The topics, by name.
    pub topics: Vec<TopicInfo>,
    /// Messages in all.
    pub messages: u64,
    /// The first and last log time of any message (0 for an empty bag).
    pub start_ns: u64,
    /// See `start_ns`.
    pub end_ns: u64,
    /// Every frame named by a header or a transform.
    pub frames: BTreeSet<String>,
    /// The (parent, child) frame pairs of `/tf` and `/tf_static` transforms.
    pub transforms: BTreeSet<(String, String)>,
}

impl BagInfo {
    /// Reads every message of `bag` once, decoding the headers of stamped types and the
    /// transforms of `tf2_msgs/TFMessage`.
    ///
    /// # Errors
    /// The bag's errors, and a [`BagError::Message`] for a header or transform that does not
    /// decode.
    pub fn of(bag: &Bag) -> Result<BagInfo, BagError> {
        let mut topics: BTreeMap<String, TopicInfo> = BTreeMap::new();
        let mut info = BagInfo::default();
        bag.for_each_message(|m| {
            let t = topics.entry(m.topic.to_owned()).or_insert_with(|| TopicInfo {
                topic: m.topic.to_owned(),
                type_name: m.type_name.to_owned(),
                count: 0,
                first_ns: m.log_time_ns,
                last_ns: m.log_time_ns,
                frames: BTreeSet::new(),
            });
            t.count += 1;
            t.first_ns = t.first_ns.min(m.log_time_ns);
            t.last_ns = t.last_ns.max(m.log_time_ns);
            if m.type_name == TF_MESSAGE && m.encoding.is_some() {
                for tf in m.transforms()? {
                    t.frames.insert(tf.header.frame_id.clone());
                    t.frames.insert(tf.child_frame_id.clone());
                    info.transforms.insert((tf.header.frame_id, tf.child_frame_id));
                }
            } else if m.encoding.is_some()
                && let Some(h) = m.header()?
            {
                t.frames.insert(h.frame_id);
            }
            Ok(())
        })?;
        for t in topics.into_values() {
            if info.messages == 0 {
                (info.start_ns, info.end_ns) = (t.first_ns, t.last_ns);
            }
            info.messages += t.count;
            info.start_ns = info.start_ns.min(t.first_ns);
            info.end_ns = info.end_ns.max(t.last_ns);
            info.frames.extend(t.frames.iter().cloned());
            info.topics.push(t);
        }
        Ok(info)
    }
}
