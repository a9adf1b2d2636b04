// cmp_segment: PCL's organised multi-plane segmentation with one concave hull per plane, on an
// organised cloud in a camera frame; prints one JSON line (kind "planes") and writes the plane
// polygons (world frame) as the shared plane-polygon JSON.
//
//   cmp_segment SCAN.ply --polygons OUT.json [--min-inliers N] [--angle-deg A] [--dist M]
//               [--curvature C] [--depth-change M] [--smoothing PX] [--alpha M]
//
// Normals: IntegralImageNormalEstimation (covariance matrix). Segmentation:
// OrganizedMultiPlaneSegmentation::segmentAndRefine. Hulls: the inliers projected on their
// plane, ConcaveHull (dimension 2). Times: normals, segmentation and hulls separately.

#include <iostream>

#include <nlohmann/json.hpp>
#include <pcl/ModelCoefficients.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/features/integral_image_normal.h>
#include <pcl/filters/project_inliers.h>
#include <pcl/pcl_config.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>
#include <pcl/surface/concave_hull.h>

#include "io.hpp"

using json = nlohmann::json;
using Pt = pcl::PointXYZ;

int main(int argc, char **argv) {
  try {
    std::string in, polygons;
    unsigned min_inliers = 500;
    double angle_deg = 3.0, dist = 0.02, curvature = 0.05, depth_change = 0.02, smoothing = 10.0, alpha = 0.1;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
        return argv[++i];
      };
      if (a == "--polygons") polygons = next();
      else if (a == "--min-inliers") min_inliers = static_cast<unsigned>(std::stoul(next()));
      else if (a == "--angle-deg") angle_deg = std::stod(next());
      else if (a == "--dist") dist = std::stod(next());
      else if (a == "--curvature") curvature = std::stod(next());
      else if (a == "--depth-change") depth_change = std::stod(next());
      else if (a == "--smoothing") smoothing = std::stod(next());
      else if (a == "--alpha") alpha = std::stod(next());
      else if (!a.empty() && a[0] == '-') throw std::runtime_error("unknown option " + a);
      else in = a;
    }
    if (in.empty() || !(dist > 0 && angle_deg > 0 && alpha > 0 && smoothing > 0 && depth_change > 0))
      throw std::runtime_error("usage: cmp_segment SCAN.ply --polygons OUT.json [options]");
    const cmp::Cloud c = cmp::read_ply(in);
    if (c.width <= 0) throw std::runtime_error(in + " is not organised (no 'comment organized W H')");
    pcl::PointCloud<Pt>::Ptr cloud(new pcl::PointCloud<Pt>(c.width, c.height));
    cloud->is_dense = false;
    size_t valid = 0;
    for (size_t i = 0; i < c.xyz.size(); ++i) {
      (*cloud)[i] = Pt(c.xyz[i][0], c.xyz[i][1], c.xyz[i][2]);
      valid += std::isfinite(c.xyz[i][2]) ? 1 : 0;
    }
    const long rss_loaded = cmp::peak_rss_kib();

    auto t0 = cmp::Clock::now();
    pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
    pcl::IntegralImageNormalEstimation<Pt, pcl::Normal> ne;
    ne.setNormalEstimationMethod(ne.COVARIANCE_MATRIX);
    ne.setMaxDepthChangeFactor(static_cast<float>(depth_change));
    ne.setNormalSmoothingSize(static_cast<float>(smoothing));
    ne.setInputCloud(cloud);
    ne.compute(*normals);
    const double t_normals = cmp::since(t0);

    t0 = cmp::Clock::now();
    pcl::OrganizedMultiPlaneSegmentation<Pt, pcl::Normal, pcl::Label> mps;
    mps.setMinInliers(min_inliers);
    mps.setAngularThreshold(angle_deg * M_PI / 180.0);
    mps.setDistanceThreshold(dist);
    mps.setMaximumCurvature(curvature);
    mps.setInputNormals(normals);
    mps.setInputCloud(cloud);
    std::vector<pcl::PlanarRegion<Pt>, Eigen::aligned_allocator<pcl::PlanarRegion<Pt>>> regions;
    std::vector<pcl::ModelCoefficients> coeffs;
    std::vector<pcl::PointIndices> inliers, boundary;
    pcl::PointCloud<pcl::Label>::Ptr labels(new pcl::PointCloud<pcl::Label>);
    std::vector<pcl::PointIndices> label_indices;
    mps.segmentAndRefine(regions, coeffs, inliers, labels, label_indices, boundary);
    const double t_seg = cmp::since(t0);

    t0 = cmp::Clock::now();
    json planes = json::array();
    size_t n_inliers = 0, n_polygons = 0, n_vertices = 0;
    const auto &P = c.pose;
    for (size_t k = 0; k < coeffs.size(); ++k) {
      pcl::ModelCoefficients::Ptr mc(new pcl::ModelCoefficients(coeffs[k]));
      pcl::PointIndices::Ptr idx(new pcl::PointIndices(inliers[k]));
      n_inliers += idx->indices.size();
      pcl::PointCloud<Pt>::Ptr projected(new pcl::PointCloud<Pt>), hull(new pcl::PointCloud<Pt>);
      pcl::ProjectInliers<Pt> proj;
      proj.setModelType(pcl::SACMODEL_PLANE);
      proj.setInputCloud(cloud);
      proj.setIndices(idx);
      proj.setModelCoefficients(mc);
      proj.filter(*projected);
      pcl::ConcaveHull<Pt> ch;
      ch.setAlpha(alpha);
      ch.setDimension(2);
      ch.setInputCloud(projected);
      std::vector<pcl::Vertices> rings;
      ch.reconstruct(*hull, rings);
      // plane n.x + d = 0 in the data frame -> world: n' = R n, d' = d - n'.t
      const double a = mc->values[0], b = mc->values[1], cc = mc->values[2], d = mc->values[3];
      const double nx = P[0] * a + P[1] * b + P[2] * cc, ny = P[4] * a + P[5] * b + P[6] * cc,
                   nz = P[8] * a + P[9] * b + P[10] * cc;
      const double norm = std::sqrt(nx * nx + ny * ny + nz * nz);
      const double dw = (d - (nx * P[3] + ny * P[7] + nz * P[11])) / norm;
      json polys = json::array();
      for (const auto &ring : rings) {
        json r = json::array();
        for (auto v : ring.vertices) {
          const auto &q = (*hull)[v];
          const cmp::V3 w = c.world(q.x, q.y, q.z);
          r.push_back({w[0], w[1], w[2]});
        }
        n_vertices += ring.vertices.size();
        ++n_polygons;
        polys.push_back(r);
      }
      planes.push_back({{"normal", {nx / norm, ny / norm, nz / norm}}, {"d", dw},
                        {"inliers", idx->indices.size()}, {"polygons", polys}});
    }
    const double t_hull = cmp::since(t0);
    const std::string tool = "pcl-" PCL_VERSION_PRETTY;
    if (!polygons.empty()) {
      std::ofstream f(polygons);
      f << json({{"tool", tool}, {"method", "omps"}, {"map", cmp::stem(in)}, {"planes", planes}}).dump() << "\n";
      if (!f) throw std::runtime_error("cannot write " + polygons);
    }
    const json row = {{"kind", "planes"},
                      {"tool", tool},
                      {"method", "omps+concave-hull"},
                      {"map", cmp::stem(in)},
                      {"points", valid},
                      {"organized", true},
                      {"planes", coeffs.size()},
                      {"inliers", n_inliers},
                      {"polygons", n_polygons},
                      {"polygon_vertices", n_vertices},
                      {"time_normals_s", t_normals},
                      {"time_seg_s", t_seg},
                      {"time_hull_s", t_hull},
                      {"time_s", t_normals + t_seg + t_hull},
                      {"rss_after_load_kib", rss_loaded},
                      {"peak_rss_kib", cmp::peak_rss_kib()},
                      {"params",
                       {{"min_inliers", min_inliers}, {"angle_deg", angle_deg}, {"dist", dist},
                        {"curvature", curvature}, {"depth_change", depth_change}, {"smoothing", smoothing},
                        {"alpha", alpha}}}};
    std::cout << row.dump() << std::endl;
    return 0;
  } catch (const std::exception &e) {
    std::cerr << "cmp_segment: " << e.what() << "\n";
    return 1;
  }
}
