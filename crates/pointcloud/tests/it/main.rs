//! Integration tests of `pointcloud`, one binary (`cargo test -p patchnav-pointcloud --test it`).

mod cloud_paths;
mod common;
mod depth_png;
mod kitti;
mod obj;
mod pcd;
mod ply;
mod pointcloud2;
mod real_data;
mod uos;
mod xyz;
