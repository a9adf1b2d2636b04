//! Plane Hough transform for terrain classification (thesis Ch. 4) (being written).
