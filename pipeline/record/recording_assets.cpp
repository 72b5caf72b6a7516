// Design: see recording_assets.h.
#include "pipeline/record/recording_assets.h"

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "formats/joints_yaml.h"
#include "formats/rig_yaml.h"
#include "formats/targets_yaml.h"

namespace mocap::record {

namespace fs = std::filesystem;

Expected<void> prepare_output_dir(const std::string& dir) {
  if (dir.empty()) return make_error("mocap record", "--out", "must name a folder");
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (fs::exists(st)) {
    if (!fs::is_directory(st)) return make_error(dir, "", "exists and is not a folder");
    fs::directory_iterator it(dir, ec);
    if (ec) return make_error(dir, "cannot read", ec.message());
    if (it != fs::directory_iterator())
      return make_error(dir, "",
                        "exists and is not empty (mocap record never overwrites; choose a new "
                        "or empty folder)");
    return {};
  }
  if (!fs::create_directories(dir, ec) || ec)
    return make_error(dir, "cannot create", ec ? ec.message() : std::string("unknown error"));
  return {};
}

namespace {

Expected<void> copy_file(const std::string& from, const std::string& to) {
  std::error_code ec;
  fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
  if (ec) return make_error(to, "cannot copy " + from, ec.message());
  return {};
}

}  // namespace

Expected<std::vector<std::string>> write_recording_assets(const std::string& dir,
                                                          const config::RunConfig& cfg,
                                                          const config::TrackingAssets& assets) {
  std::vector<std::string> written;
  if (auto r = save_rig(dir + "/rig.yaml", assets.rig); !r) return r.error();
  written.push_back("rig.yaml");
  if (assets.targets.bodies.empty()) return written;  // recorded before any target exists
  if (!cfg.targets_path.empty()) {
    if (auto r = copy_file(cfg.targets_path, dir + "/targets.yaml"); !r) return r.error();
  } else if (auto r = save_targets(dir + "/targets.yaml", assets.targets); !r) {
    return r.error();
  }
  written.push_back("targets.yaml");
  if (!assets.model) return written;
  if (!cfg.model_path.empty()) {
    if (auto r = copy_file(cfg.model_path, dir + "/model.yaml"); !r) return r.error();
  } else if (auto r = save_model(dir + "/model.yaml", *assets.model); !r) {
    return r.error();
  }
  written.push_back("model.yaml");
  // joints.yaml: a joints.yaml next to the configured model, else the model's topology.
  const std::string sibling =
      cfg.model_path.empty() ? std::string()
                             : (fs::path(cfg.model_path).parent_path() / "joints.yaml").string();
  std::error_code ec;
  if (!sibling.empty() && fs::is_regular_file(sibling, ec)) {
    if (auto r = copy_file(sibling, dir + "/joints.yaml"); !r) return r.error();
  } else {
    JointModel topology = *assets.model;
    for (JointSpec& j : topology.joints) j.calibrated = false;
    if (auto r = save_model(dir + "/joints.yaml", topology); !r) return r.error();
  }
  written.push_back("joints.yaml");
  return written;
}

}  // namespace mocap::record
