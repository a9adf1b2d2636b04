// Readers of the shared exchange format (OBJ triangle meshes, PLY clouds with the
// `organized` / `sensor_origin` / `sensor_to_world` comments) and small helpers common to the
// comparison programs. Every reader throws std::runtime_error on bad input.
#pragma once

#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace cmp {

using V3 = std::array<double, 3>;

/// A triangle soup: vertices in metres, 0-based corner indices.
struct Mesh {
  std::vector<V3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

/// Wavefront OBJ: `v` and `f` lines only (`a/b/c` takes `a`, negative indices count from the
/// end, polygons are fan-triangulated); every other line is ignored.
inline Mesh read_obj(const std::string &path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  Mesh m;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    if (!(ls >> tag)) continue;
    if (tag == "v") {
      V3 v{};
      if (!(ls >> v[0] >> v[1] >> v[2]) || !std::isfinite(v[0] + v[1] + v[2]))
        throw std::runtime_error(path + ": bad vertex line: " + line);
      m.vertices.push_back(v);
    } else if (tag == "f") {
      std::vector<int> idx;
      for (std::string tok; ls >> tok;) {
        long i = std::strtol(tok.substr(0, tok.find('/')).c_str(), nullptr, 10);
        i = i > 0 ? i - 1 : static_cast<long>(m.vertices.size()) + i;
        if (i < 0 || i >= static_cast<long>(m.vertices.size()))
          throw std::runtime_error(path + ": face index out of range: " + line);
        idx.push_back(static_cast<int>(i));
      }
      for (size_t k = 2; k < idx.size(); ++k) m.triangles.push_back({idx[0], idx[k - 1], idx[k]});
    }
  }
  if (m.triangles.empty()) throw std::runtime_error(path + ": no triangles");
  return m;
}

/// A cloud as read from PLY: x, y, z of element `vertex` (NaN = no measurement).
struct Cloud {
  std::vector<std::array<float, 3>> xyz;
  int width = 0, height = 0;  // organised when both > 0
  bool has_origin = false;
  V3 origin{0, 0, 0};  // sensor origin in the data frame
  std::array<double, 12> pose{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};  // data -> world, row-major [R|t]

  V3 world(double x, double y, double z) const {
    return {pose[0] * x + pose[1] * y + pose[2] * z + pose[3], pose[4] * x + pose[5] * y + pose[6] * z + pose[7],
            pose[8] * x + pose[9] * y + pose[10] * z + pose[11]};
  }
  /// The sensor origin in the world frame (the data frame's origin when no comment gives it).
  V3 world_origin() const { return world(origin[0], origin[1], origin[2]); }
};

/// PLY, ascii or binary (either endianness): x, y, z of `vertex` of any numeric type; other
/// properties and elements are skipped (list properties only after `vertex`).
inline Cloud read_ply(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path);
  struct Prop {
    std::string type, name;
  };
  std::vector<Prop> props;
  size_t count = 0;
  bool in_vertex = false, seen_vertex = false;
  std::string line, format;
  Cloud c;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0) throw std::runtime_error(path + " is not PLY");
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string tag, key;
    ls >> tag;
    if (tag == "format") {
      ls >> format;
    } else if (tag == "comment") {
      ls >> key;
      if (key == "organized") ls >> c.width >> c.height;
      if (key == "sensor_origin") c.has_origin = static_cast<bool>(ls >> c.origin[0] >> c.origin[1] >> c.origin[2]);
      if (key == "sensor_to_world") {
        for (double &x : c.pose) ls >> x;
        if (!ls) throw std::runtime_error(path + ": sensor_to_world needs 12 numbers");
      }
    } else if (tag == "element") {
      std::string name;
      ls >> name;
      in_vertex = name == "vertex" && !seen_vertex;
      if (in_vertex) {
        ls >> count;
        seen_vertex = true;
      }
    } else if (tag == "property" && in_vertex) {
      Prop p;
      ls >> p.type >> p.name;
      if (p.type == "list") throw std::runtime_error(path + ": list property in vertex");
      props.push_back(p);
    } else if (tag == "end_header") {
      break;
    }
  }
  if (!seen_vertex) throw std::runtime_error(path + ": no vertex element");
  auto size_of = [&](const std::string &t) -> int {
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
    if (t == "double" || t == "float64") return 8;
    throw std::runtime_error(path + ": unknown PLY type " + t);
  };
  const bool ascii = format == "ascii", big = format == "binary_big_endian";
  if (!ascii && !big && format != "binary_little_endian") throw std::runtime_error(path + ": format " + format);
  int ix = -1, iy = -1, iz = -1;
  for (size_t k = 0; k < props.size(); ++k) {
    if (props[k].name == "x") ix = static_cast<int>(k);
    if (props[k].name == "y") iy = static_cast<int>(k);
    if (props[k].name == "z") iz = static_cast<int>(k);
  }
  if (ix < 0 || iy < 0 || iz < 0) throw std::runtime_error(path + ": vertex without x y z");
  auto value = [&](const std::string &t) -> double {
    if (ascii) {
      std::string tok;
      if (!(in >> tok)) throw std::runtime_error(path + ": truncated");
      return std::strtod(tok.c_str(), nullptr);
    }
    unsigned char b[8];
    const int n = size_of(t);
    if (!in.read(reinterpret_cast<char *>(b), n)) throw std::runtime_error(path + ": truncated");
    if (big) std::reverse(b, b + n);
    if (t == "float" || t == "float32") { float f; std::memcpy(&f, b, 4); return f; }
    if (t == "double" || t == "float64") { double d; std::memcpy(&d, b, 8); return d; }
    if (n == 1) return (t == "char" || t == "int8") ? static_cast<int8_t>(b[0]) : b[0];
    if (n == 2) { int16_t s; uint16_t u; std::memcpy(&s, b, 2); std::memcpy(&u, b, 2); return (t == "short" || t == "int16") ? s : u; }
    int32_t s; uint32_t u; std::memcpy(&s, b, 4); std::memcpy(&u, b, 4);
    return (t == "int" || t == "int32") ? static_cast<double>(s) : static_cast<double>(u);
  };
  c.xyz.reserve(count);
  std::vector<double> row(props.size());
  for (size_t i = 0; i < count; ++i) {
    for (size_t k = 0; k < props.size(); ++k) row[k] = value(props[k].type);
    c.xyz.push_back({static_cast<float>(row[ix]), static_cast<float>(row[iy]), static_cast<float>(row[iz])});
  }
  if (c.width > 0 && static_cast<size_t>(c.width) * c.height != c.xyz.size())
    throw std::runtime_error(path + ": organized size does not match the vertex count");
  return c;
}

inline std::string stem(const std::string &p) {
  const auto slash = p.find_last_of('/');
  std::string b = slash == std::string::npos ? p : p.substr(slash + 1);
  return b.substr(0, b.find_last_of('.'));
}

inline std::string parent(const std::string &p) {
  const auto slash = p.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : p.substr(0, slash);
}

using Clock = std::chrono::steady_clock;
inline double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// Peak resident set size of this process so far, KiB.
inline long peak_rss_kib() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss;
}

}  // namespace cmp
