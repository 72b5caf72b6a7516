// Design: rig.yaml reader/writer (see rig_yaml.h and docs/formats.md). The reader
// validates every field and reports the first problem as one line. A hand-written R
// that is orthonormal only to ~1e-4 (rounded digits) is re-orthonormalised with an SVD;
// beyond that, or with det < 0, it is rejected with the size of the error.
#include "formats/rig_yaml.h"

#include <Eigen/SVD>
#include <cmath>
#include <cstdio>
#include <set>

#include "core/camera_set.h"
#include "formats/pgm.h"
#include "formats/text_io.h"
#include "formats/yaml_read.h"

namespace mocap {
namespace {

using namespace formats_detail;

// Largest |(R^T R - I)_ij| below which R is kept bit for bit, and up to which it is
// re-orthonormalised (rounding of hand-written or printed matrices).
constexpr double kKeepExactTol = 1e-9;
constexpr double kOrthonormaliseTol = 1e-4;

Mat3 checked_rotation(const std::vector<double>& v, const YAML::Node& node,
                      const std::string& where) {
  Mat3 R;
  R << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
  const double ortho_err = (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff();
  const double det = R.determinant();
  char buf[160];
  if (det <= 0.0) {
    std::snprintf(buf, sizeof buf, "not a rotation (det = %.6f, must be +1)", det);
    fail(where, buf + line_suffix(node));
  }
  if (ortho_err > kOrthonormaliseTol) {
    std::snprintf(buf, sizeof buf,
                  "not a rotation (max |R^T R - I| = %.3g, tolerance %.0e; det = %.6f)", ortho_err,
                  kOrthonormaliseTol, det);
    fail(where, buf + line_suffix(node));
  }
  if (ortho_err <= kKeepExactTol) return R;
  const Eigen::JacobiSVD<Mat3> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();  // det > 0 was checked above
}

double positive(double v, const YAML::Node& node, const std::string& where) {
  if (!(v > 0.0)) fail(where, "must be > 0, got " + format_double(v) + line_suffix(node));
  return v;
}

CameraModel parse_camera(const YAML::Node& cam_node, const std::string& where) {
  require_map(cam_node, where);
  CameraModel cam;
  auto key = [&](const char* k) { return require_key(cam_node, where, k); };
  auto kp = [&](const char* k) { return key_path(where, k); };

  cam.name = get_string(key("name"), kp("name"));
  if (const std::string p = name_problem(cam.name); !p.empty()) {
    fail(kp("name"), p + line_suffix(key("name")));
  }
  for (const char* k : {"width", "height"}) {
    const YAML::Node n = key(k);
    const std::int64_t v = get_int(n, kp(k));
    if (v <= 0 || v > kMaxImageSidePx) {
      fail(kp(k), "must be in 1.." + std::to_string(kMaxImageSidePx) + " pixels, got " +
                      std::to_string(v) + line_suffix(n));
    }
    (k[0] == 'w' ? cam.width : cam.height) = static_cast<int>(v);
  }
  cam.fx = positive(get_double(key("fx"), kp("fx")), key("fx"), kp("fx"));
  cam.fy = positive(get_double(key("fy"), kp("fy")), key("fy"), kp("fy"));
  cam.cx = get_double(key("cx"), kp("cx"));
  cam.cy = get_double(key("cy"), kp("cy"));
  const std::vector<double> d = get_doubles(key("distortion"), kp("distortion"), 5);
  for (std::size_t i = 0; i < 5; ++i) cam.distortion[i] = d[i];
  cam.R_cam_world = checked_rotation(get_doubles(key("R"), kp("R"), 9), key("R"), kp("R"));
  cam.t_cam_world = get_vec3(key("t"), kp("t"));
  return cam;
}

void append_list(std::string& out, const double* v, std::size_t n) {
  out += '[';
  for (std::size_t i = 0; i < n; ++i) {
    if (i) out += ", ";
    append_double(out, v[i]);
  }
  out += ']';
}

}  // namespace

Expected<Rig> load_rig(const std::string& path) {
  auto root = load_yaml_map(path);
  if (!root) return root.error();
  return guard<Rig>(path, [&]() -> Expected<Rig> {
    const YAML::Node cams = require_key(*root, "", "cameras");
    require_list(cams, "cameras");
    if (cams.size() == 0)
      fail("cameras", "empty list (at least one camera is needed)" + line_suffix(cams));
    if (cams.size() > static_cast<std::size_t>(kMaxCameras))
      fail("cameras", std::to_string(cams.size()) + " cameras, at most " +
                          std::to_string(kMaxCameras) + " are supported" + line_suffix(cams));
    Rig rig;
    std::set<std::string> names;
    for (std::size_t i = 0; i < cams.size(); ++i) {
      const std::string where = index_path("cameras", i);
      CameraModel cam = parse_camera(cams[i], where);
      if (!names.insert(cam.name).second) {
        fail(key_path(where, "name"),
             "duplicate camera name '" + cam.name + "'" + line_suffix(cams[i]));
      }
      rig.cameras.push_back(std::move(cam));
    }
    return rig;
  });
}

Expected<void> save_rig(const std::string& path, const Rig& rig) {
  std::string out =
      "# Camera rig (mocap rig.yaml): intrinsics in pixels, OpenCV distortion\n"
      "# [k1, k2, p1, p2, k3], extrinsics world -> camera (R row-major, t in mm).\n"
      "cameras:\n";
  for (const CameraModel& c : rig.cameras) {
    out += "  - name: " + yaml_string(c.name) + "\n";
    out += "    width: " + std::to_string(c.width) + "\n";
    out += "    height: " + std::to_string(c.height) + "\n";
    const std::pair<const char*, double> scalars[] = {
        {"fx", c.fx}, {"fy", c.fy}, {"cx", c.cx}, {"cy", c.cy}};
    for (const auto& [k, v] : scalars) {
      out += std::string("    ") + k + ": ";
      append_double(out, v);
      out += '\n';
    }
    out += "    distortion: ";
    append_list(out, c.distortion.data(), c.distortion.size());
    out += "\n    R: ";
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> Rr = c.R_cam_world;
    append_list(out, Rr.data(), 9);
    out += "\n    t: ";
    append_list(out, c.t_cam_world.data(), 3);
    out += '\n';
  }
  return write_text_file(path, out);
}

}  // namespace mocap
