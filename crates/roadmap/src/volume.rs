//! Explored volume (thesis §6.1.1): roadmaps rasterised into a sparse voxel grid.
