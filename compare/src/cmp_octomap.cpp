// cmp_octomap: one OctoMap OcTree from several posed scans, each inserted as ray casts from its
// sensor origin (OcTree::insertPointCloud); prints one JSON line (kind "volumetric").
//
//   cmp_octomap SCAN.ply [SCAN.ply ...] --resolution M [--max-range M] [--out MAP.bt]
//
// Points go to the world frame with the PLY's `comment sensor_to_world`; the sensor origin is
// `comment sensor_origin` (default: the data frame's origin) in the world frame. After all scans
// the tree is pruned; the line gives the insertion time, OctoMap's memoryUsage(), node counts
// and the size of the binary (.bt, maximum-likelihood) serialisation.

#include <fstream>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>
#include <octomap/octomap.h>

#include "io.hpp"

using json = nlohmann::json;

int main(int argc, char **argv) {
  try {
    std::vector<std::string> scans;
    double res = 0.05, max_range = -1;
    std::string out;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
        return argv[++i];
      };
      if (a == "--resolution") res = std::stod(next());
      else if (a == "--max-range") max_range = std::stod(next());
      else if (a == "--out") out = next();
      else if (!a.empty() && a[0] == '-') throw std::runtime_error("unknown option " + a);
      else scans.push_back(a);
    }
    if (scans.empty() || !(res > 0.001 && res < 100))
      throw std::runtime_error("usage: cmp_octomap SCAN.ply... --resolution M [--max-range M] [--out MAP.bt]");
    std::vector<cmp::Cloud> clouds;
    for (const auto &s : scans) clouds.push_back(cmp::read_ply(s));
    const long rss_loaded = cmp::peak_rss_kib();

    octomap::OcTree tree(res);
    size_t points = 0;
    double time_s = 0;
    for (const auto &c : clouds) {
      octomap::Pointcloud pc;
      for (const auto &p : c.xyz) {
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) continue;
        const cmp::V3 w = c.world(p[0], p[1], p[2]);
        pc.push_back(static_cast<float>(w[0]), static_cast<float>(w[1]), static_cast<float>(w[2]));
      }
      points += pc.size();
      const cmp::V3 o = c.world_origin();
      const auto t0 = cmp::Clock::now();
      tree.insertPointCloud(pc, octomap::point3d(o[0], o[1], o[2]), max_range);
      time_s += cmp::since(t0);
    }
    const auto t0 = cmp::Clock::now();
    tree.prune();
    time_s += cmp::since(t0);

    size_t occupied = 0, free = 0;
    for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it)
      (tree.isNodeOccupied(*it) ? occupied : free)++;
    std::ostringstream bt;
    tree.writeBinaryConst(bt);
    const std::string bytes = bt.str();
    if (!out.empty()) {
      std::ofstream f(out, std::ios::binary);
      f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      if (!f) throw std::runtime_error("cannot write " + out);
    }
    const json row = {{"kind", "volumetric"},
                      {"tool", "octomap-" CMP_OCTOMAP_VERSION},
                      {"method", "insertPointCloud"},
                      {"map", cmp::stem(scans.front())},
                      {"scans", scans.size()},
                      {"points", points},
                      {"resolution", res},
                      {"time_s", time_s},
                      {"memory_usage_bytes", tree.memoryUsage()},
                      {"nodes", tree.calcNumNodes()},
                      {"leaf_nodes", tree.getNumLeafNodes()},
                      {"occupied_leaves", occupied},
                      {"free_leaves", free},
                      {"bt_bytes", bytes.size()},
                      {"rss_after_load_kib", rss_loaded},
                      {"peak_rss_kib", cmp::peak_rss_kib()}};
    std::cout << row.dump() << std::endl;
    return 0;
  } catch (const std::exception &e) {
    std::cerr << "cmp_octomap: " << e.what() << "\n";
    return 1;
  }
}
