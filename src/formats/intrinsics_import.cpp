// Design: the importers of intrinsics_import.h. Every matrix goes through read_matrix()
// (an !!opencv-matrix / ROS {rows, cols, data} map, or a plain list of the expected
// size); the camera is checked like rig.yaml (positive focal lengths, finite values,
// supported distortion). Errors are one line "<file>: key: problem".
#include "formats/intrinsics_import.h"

#include <Eigen/SVD>
#include <cmath>

#include "formats/rig_yaml.h"
#include "formats/text_io.h"
#include "formats/yaml_read.h"

namespace mocap {

using namespace formats_detail;

namespace {

// rows x cols matrix (row-major) from a {rows, cols, data} map or a plain list.
std::vector<double> read_matrix(const YAML::Node& node, const std::string& where, int rows,
                                int cols) {
  const int n = rows * cols;
  if (node.IsSequence()) return get_doubles(node, where, n);
  require_map(node, where);
  const auto r = get_int(require_key(node, where, "rows"), key_path(where, "rows"));
  const auto c = get_int(require_key(node, where, "cols"), key_path(where, "cols"));
  // Vectors may be stored as 1xN or Nx1.
  const bool ok = (r == rows && c == cols) || (rows == 1 && r == cols && c == 1) ||
                  (cols == 1 && c == rows && r == 1);
  if (!ok)
    fail(where, "expected a " + std::to_string(rows) + "x" + std::to_string(cols) +
                    " matrix, got " + std::to_string(r) + "x" + std::to_string(c) +
                    line_suffix(node));
  if (has_key(node, "dt")) {
    const std::string dt = get_string(require_key(node, where, "dt"), key_path(where, "dt"));
    if (dt != "d" && dt != "f")
      fail(key_path(where, "dt"), "element type '" + dt + "' is not a float type (d or f)");
  }
  return get_doubles(require_key(node, where, "data"), key_path(where, "data"), n);
}

// A distortion vector of any length (1xN / Nx1 / list) -> [k1 k2 p1 p2 k3].
std::array<double, 5> read_distortion(const YAML::Node& node, const std::string& where) {
  std::vector<double> d;
  if (node.IsSequence()) {
    d = get_doubles(node, where, -1);
  } else {
    require_map(node, where);
    const auto r = get_int(require_key(node, where, "rows"), key_path(where, "rows"));
    const auto c = get_int(require_key(node, where, "cols"), key_path(where, "cols"));
    if (r < 1 || c < 1 || (r != 1 && c != 1))
      fail(where, "expected a vector (1xN or Nx1)" + line_suffix(node));
    d = get_doubles(require_key(node, where, "data"), key_path(where, "data"),
                    static_cast<int>(r * c));
  }
  if (d.size() != 4 && d.size() != 5 && d.size() != 8 && d.size() != 12 && d.size() != 14)
    fail(where, "expected 4, 5, 8, 12 or 14 coefficients, got " + std::to_string(d.size()) +
                    line_suffix(node));
  for (std::size_t i = 5; i < d.size(); ++i) {
    if (d[i] != 0.0)
      fail(where, "coefficient " + std::to_string(i) +
                      " is non-zero: only the 5-parameter model [k1 k2 p1 p2 k3] is supported" +
                      line_suffix(node));
  }
  std::array<double, 5> out{};
  for (std::size_t i = 0; i < std::min<std::size_t>(5, d.size()); ++i) out[i] = d[i];
  return out;
}

void set_camera_matrix(CameraModel& cam, const std::vector<double>& K, const std::string& where) {
  if (!(K[0] > 0.0) || !(K[4] > 0.0))
    fail(where, "focal lengths must be > 0, got fx " + format_double(K[0]) + ", fy " +
                    format_double(K[4]));
  if (K[1] != 0.0) fail(where, "non-zero skew K[0][1] is not supported");
  if (K[3] != 0.0 || K[6] != 0.0 || K[7] != 0.0 || K[8] != 1.0)
    fail(where, "not a camera matrix (last row must be 0 0 1, K[1][0] must be 0)");
  cam.fx = K[0];
  cam.fy = K[4];
  cam.cx = K[2];
  cam.cy = K[5];
}

const char* first_key(const YAML::Node& root, std::initializer_list<const char*> keys) {
  for (const char* k : keys) {
    if (has_key(root, k)) return k;
  }
  return nullptr;
}

void read_size(const YAML::Node& root, CameraModel& cam) {
  if (has_key(root, "image_width") || has_key(root, "image_height")) {
    cam.width = static_cast<int>(get_int(require_key(root, "", "image_width"), "image_width"));
    cam.height = static_cast<int>(get_int(require_key(root, "", "image_height"), "image_height"));
  } else if (const char* k = first_key(root, {"imageSize", "image_size"})) {
    const auto v = get_doubles(require_key(root, "", k), k, 2);
    cam.width = static_cast<int>(v[0]);
    cam.height = static_cast<int>(v[1]);
  }
  if (cam.width < 0 || cam.height < 0 || cam.width > 16384 || cam.height > 16384)
    fail("image_width", "image size out of range");
}

// Files print rotations with a few digits: accept |R R^T - I| <= 1e-3 and return the
// nearest rotation (SVD projection).
Mat3 check_rotation(const std::vector<double>& r, const std::string& where) {
  Mat3 R;
  for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = r[static_cast<std::size_t>(i)];
  const double err = (R * R.transpose() - Mat3::Identity()).norm();
  if (err > 1e-3 || std::fabs(R.determinant() - 1.0) > 1e-3)
    fail(where, "not a rotation matrix (|R R^T - I| = " + format_double(err) + ")");
  Eigen::JacobiSVD<Mat3> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

Expected<YAML::Node> parse_opencv_text(const std::string& path) {
  std::string text;
  if (auto r = read_text_file(path, text); !r) return r.error();
  // "%YAML:1.0" is OpenCV's own spelling of the directive: yaml-cpp rejects it. Replace
  // the line by a comment so that line numbers stay right.
  if (text.rfind("%YAML:", 0) == 0 || text.rfind("%YAML 1.0", 0) == 0) text.insert(0, "#");
  return guard<YAML::Node>(path, [&]() -> Expected<YAML::Node> {
    YAML::Node root = YAML::Load(text);
    if (!root.IsDefined() || root.IsNull()) return make_error(path, "", "empty file");
    if (!root.IsMap()) fail("top level", "expected a map, got " + describe(root));
    check_unique_keys(root, "top level");
    return root;
  });
}

Expected<ImportedIntrinsics> opencv_from_root(const std::string& path, const YAML::Node& root) {
  return guard<ImportedIntrinsics>(path, [&]() -> Expected<ImportedIntrinsics> {
    ImportedIntrinsics out;
    out.format = IntrinsicsFormat::kOpenCv;
    CameraModel proto;
    read_size(root, proto);
    const char* k_single = first_key(root, {"camera_matrix", "cameraMatrix", "K", "M"});
    const char* k_stereo0 = first_key(root, {"M1", "K1", "cameraMatrix1", "camera_matrix_1"});
    if (k_single != nullptr && k_stereo0 == nullptr) {
      CameraModel cam = proto;
      cam.name = "cam0";
      set_camera_matrix(cam, read_matrix(require_key(root, "", k_single), k_single, 3, 3),
                        k_single);
      const char* kd =
          first_key(root, {"distortion_coefficients", "distCoeffs", "dist_coeffs", "D", "dist"});
      if (kd == nullptr)
        fail("distortion_coefficients", "missing key (also looked for distCoeffs, D, dist)");
      cam.distortion = read_distortion(require_key(root, "", kd), kd);
      out.cameras.push_back(cam);
    } else if (k_stereo0 != nullptr) {
      const std::string s(k_stereo0);
      const std::string base = s.substr(0, s.size() - 1);  // "M", "K", "cameraMatrix", ...
      const std::string dbase = base == "cameraMatrix"     ? "distCoeffs"
                                : base == "camera_matrix_" ? "distortion_coefficients_"
                                                           : "D";
      for (int c = 0; c < 2; ++c) {
        const std::string km = base + std::to_string(c + 1);
        const std::string kd = dbase + std::to_string(c + 1);
        CameraModel cam = proto;
        cam.name = "cam" + std::to_string(c);
        set_camera_matrix(cam, read_matrix(require_key(root, "", km), km, 3, 3), km);
        cam.distortion = read_distortion(require_key(root, "", kd), kd);
        out.cameras.push_back(cam);
      }
    } else {
      fail("camera_matrix",
           "missing key (looked for camera_matrix, cameraMatrix, K, M, and M1/K1/cameraMatrix1 "
           "for a stereo pair)");
    }
    if (has_key(root, "R") || has_key(root, "T")) {
      const auto r = read_matrix(require_key(root, "", "R"), "R", 3, 3);
      out.R_1_0 = check_rotation(r, "R");
      const auto t = read_matrix(require_key(root, "", "T"), "T", 3, 1);
      out.has_relative_pose = true;
      out.t_1_0_mm = Vec3(t[0], t[1], t[2]);
      if (!(out.t_1_0_mm.norm() > 0.0)) fail("T", "zero baseline");
    }
    return out;
  });
}

struct RosCamera {
  CameraModel cam;
  Mat3 R_rect = Mat3::Identity();
  double P03 = 0.0, P00 = 0.0, P13 = 0.0;
  bool has_rect = false, has_P = false;
};

Expected<RosCamera> read_ros(const std::string& path) {
  auto root = load_yaml_map(path);
  if (!root) return root.error();
  return guard<RosCamera>(path, [&]() -> Expected<RosCamera> {
    RosCamera rc;
    CameraModel& cam = rc.cam;
    cam.width = static_cast<int>(get_int(require_key(*root, "", "image_width"), "image_width"));
    cam.height = static_cast<int>(get_int(require_key(*root, "", "image_height"), "image_height"));
    if (cam.width < 1 || cam.height < 1 || cam.width > 16384 || cam.height > 16384)
      fail("image_width", "image size out of range");
    cam.name = has_key(*root, "camera_name")
                   ? get_string(require_key(*root, "", "camera_name"), "camera_name")
                   : "cam0";
    set_camera_matrix(cam,
                      read_matrix(require_key(*root, "", "camera_matrix"), "camera_matrix", 3, 3),
                      "camera_matrix");
    std::string model = "plumb_bob";
    if (has_key(*root, "distortion_model"))
      model = get_string(require_key(*root, "", "distortion_model"), "distortion_model");
    if (model != "plumb_bob" && model != "rational_polynomial")
      fail("distortion_model",
           "'" + model + "' is not supported (plumb_bob or rational_polynomial)");
    cam.distortion = read_distortion(require_key(*root, "", "distortion_coefficients"),
                                     "distortion_coefficients");
    if (has_key(*root, "rectification_matrix")) {
      const auto r =
          read_matrix(require_key(*root, "", "rectification_matrix"), "rectification_matrix", 3, 3);
      rc.R_rect = check_rotation(r, "rectification_matrix");
      rc.has_rect = true;
    }
    if (has_key(*root, "projection_matrix")) {
      const auto p =
          read_matrix(require_key(*root, "", "projection_matrix"), "projection_matrix", 3, 4);
      rc.P00 = p[0];
      rc.P03 = p[3];
      rc.P13 = p[7];
      rc.has_P = true;
      if (!(p[0] > 0.0)) fail("projection_matrix", "P[0][0] must be > 0");
    }
    return rc;
  });
}

}  // namespace

Expected<ImportedIntrinsics> import_opencv_yaml(const std::string& path) {
  auto root = parse_opencv_text(path);
  if (!root) return root.error();
  return opencv_from_root(path, *root);
}

Expected<ImportedIntrinsics> import_ros_camera_info(const std::string& path) {
  auto rc = read_ros(path);
  if (!rc) return rc.error();
  ImportedIntrinsics out;
  out.format = IntrinsicsFormat::kRosCameraInfo;
  out.cameras.push_back(rc->cam);
  return out;
}

Expected<ImportedIntrinsics> import_ros_stereo(const std::string& left_path,
                                               const std::string& right_path) {
  auto l = read_ros(left_path);
  if (!l) return l.error();
  auto r = read_ros(right_path);
  if (!r) return r.error();
  if (!l->has_rect || !r->has_rect)
    return make_error(l->has_rect ? right_path : left_path, "rectification_matrix",
                      "missing key (needed for the pair's relative pose)");
  if (!r->has_P) return make_error(right_path, "projection_matrix", "missing key");
  if (!(r->P03 < 0.0))
    return make_error(right_path, "projection_matrix",
                      "P[0][3] = -fx * baseline must be < 0 for the right camera");
  ImportedIntrinsics out;
  out.format = IntrinsicsFormat::kRosCameraInfo;
  out.cameras = {l->cam, r->cam};
  if (out.cameras[0].name == out.cameras[1].name) {
    out.cameras[0].name += "_left";
    out.cameras[1].name += "_right";
  }
  // X_rect_r = X_rect_l - (B, 0, 0) with B = -P03 / P00 metres (ROS convention).
  const Vec3 b_m(-r->P03 / r->P00, -r->P13 / r->P00, 0.0);
  out.has_relative_pose = true;
  out.R_1_0 = r->R_rect.transpose() * l->R_rect;
  out.t_1_0_mm = -r->R_rect.transpose() * b_m * 1000.0;
  return out;
}

Expected<ImportedIntrinsics> import_intrinsics(const std::string& path) {
  auto root = parse_opencv_text(path);
  if (!root) return root.error();
  if (has_key(*root, "cameras")) {
    auto rig = load_rig(path);
    if (!rig) return rig.error();
    ImportedIntrinsics out;
    out.format = IntrinsicsFormat::kRigYaml;
    out.cameras = rig->cameras;
    if (out.cameras.size() >= 2) {
      const Iso3 T_1_0 = out.cameras[1].T_cam_world() * out.cameras[0].T_cam_world().inverse();
      out.has_relative_pose = (T_1_0.translation().norm() > 0.0);
      out.R_1_0 = T_1_0.linear();
      out.t_1_0_mm = T_1_0.translation();
    }
    for (CameraModel& c : out.cameras) {
      c.R_cam_world = Mat3::Identity();
      c.t_cam_world = Vec3::Zero();
    }
    return out;
  }
  if (has_key(*root, "distortion_model") ||
      (has_key(*root, "camera_name") && has_key(*root, "camera_matrix")))
    return import_ros_camera_info(path);
  return opencv_from_root(path, *root);
}

}  // namespace mocap
