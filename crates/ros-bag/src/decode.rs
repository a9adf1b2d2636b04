//! Decoding a stored message into this workspace's types.

use crate::bag::MessageRef;
use crate::error::BagError;
use crate::image::{CAMERA_INFO, CameraInfo, IMAGE, Image};
use crate::msgs::{
    self, Header, LASER_SCAN, LaserScan, POINT_CLOUD2, PointCloud2Msg, TF_MESSAGE, TransformStamped,
};
use crate::wire::{Encoding, WireError};
use pointcloud::PointCloud;
use pointcloud::io::pointcloud2;

impl MessageRef<'_> {
    fn encoding_or_error(&self) -> Result<Encoding, BagError> {
        self.encoding.ok_or_else(|| BagError::UnknownEncoding {
            path: self.file.to_owned(),
            offset: self.offset,
            topic: self.topic.to_owned(),
        })
    }

    fn expect_type(&self, expected: &str) -> Result<Encoding, BagError> {
        if self.type_name != expected {
            return Err(BagError::WrongType {
                path: self.file.to_owned(),
                offset: self.offset,
                topic: self.topic.to_owned(),
                expected: expected.to_owned(),
                found: self.type_name.to_owned(),
            });
        }
        self.encoding_or_error()
    }

    fn wire_error(&self, source: WireError) -> BagError {
        BagError::Message {
            path: self.file.to_owned(),
            offset: self.offset,
            topic: self.topic.to_owned(),
            type_name: self.type_name.to_owned(),
            source,
        }
    }

    /// The message's `std_msgs/Header`, if its type has one ([`msgs::has_header`]).
    pub fn header(&self) -> Result<Option<Header>, BagError> {
        if !msgs::has_header(self.type_name) {
            return Ok(None);
        }
        let encoding = self.encoding_or_error()?;
        msgs::read_header(self.data, encoding).map(Some).map_err(|e| self.wire_error(e))
    }

    /// The message as a `sensor_msgs/PointCloud2` (header and layout, not yet a cloud).
    pub fn point_cloud2(&self) -> Result<PointCloud2Msg, BagError> {
        let encoding = self.expect_type(POINT_CLOUD2)?;
        PointCloud2Msg::decode(self.data, encoding).map_err(|e| self.wire_error(e))
    }

    /// The message as a cloud in its sensor frame, with its header: a `sensor_msgs/PointCloud2`
    /// (see [`pointcloud::io::pointcloud2`] for how fields map to the cloud) or a
    /// `sensor_msgs/LaserScan` (see [`LaserScan::to_cloud`]).
    pub fn cloud(&self) -> Result<(Header, PointCloud), BagError> {
        if self.type_name == LASER_SCAN {
            let encoding = self.encoding_or_error()?;
            let scan = LaserScan::decode(self.data, encoding).map_err(|e| self.wire_error(e))?;
            let cloud = scan.to_cloud().map_err(|e| BagError::Cloud {
                path: self.file.to_owned(),
                offset: self.offset,
                topic: self.topic.to_owned(),
                source: e.into(),
            })?;
            return Ok((scan.header, cloud));
        }
        let msg = self.point_cloud2()?;
        let cloud = pointcloud2::decode(&msg.cloud).map_err(|source| BagError::Cloud {
            path: self.file.to_owned(),
            offset: self.offset,
            topic: self.topic.to_owned(),
            source,
        })?;
        Ok((msg.header, cloud))
    }

    /// The message as a `sensor_msgs/CameraInfo`.
    pub fn camera_info(&self) -> Result<CameraInfo, BagError> {
        let encoding = self.expect_type(CAMERA_INFO)?;
        CameraInfo::decode(self.data, encoding).map_err(|e| self.wire_error(e))
    }

    /// The message as a `sensor_msgs/Image`.
    pub fn image(&self) -> Result<Image, BagError> {
        let encoding = self.expect_type(IMAGE)?;
        Image::decode(self.data, encoding).map_err(|e| self.wire_error(e))
    }

    /// A depth image (`sensor_msgs/Image`, `16UC1` or `32FC1`) as an organised cloud in its
    /// optical frame by the pinhole model of `info`, with its header (see [`crate::image`]).
    pub fn depth_cloud(&self, info: &CameraInfo) -> Result<(Header, PointCloud), BagError> {
        let image = self.image()?;
        let cloud = image.to_cloud(info).map_err(|source| BagError::Depth {
            path: self.file.to_owned(),
            offset: self.offset,
            topic: self.topic.to_owned(),
            source,
        })?;
        Ok((image.header, cloud))
    }

    /// The message as a `tf2_msgs/TFMessage`.
    pub fn transforms(&self) -> Result<Vec<TransformStamped>, BagError> {
        let encoding = self.expect_type(TF_MESSAGE)?;
        msgs::decode_tf(self.data, encoding).map_err(|e| self.wire_error(e))
    }
}
