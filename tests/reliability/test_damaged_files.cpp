// Broken configuration files of a recording run: rig.yaml, frames.csv, targets.yaml and
// model.yaml with syntax errors, NaN/inf/out-of-range numbers, wrong shapes, binary
// garbage and pathological nesting. `mocap track` must end with exit 2 and ONE line
// naming the file (or, for a file that is valid but degenerate, succeed with a warning
// naming it): never a crash, a hang or a multi-line dump.
#include <string>

#include "tests/reliability/damaged_fixture.h"

namespace mocap {
namespace {

using test::DamagedRecording;

enum class Which { kRig, kFrames, kTargets, kModel };

struct FileDamage {
  const char* name;
  Which file;
  const char* begin;  // the first occurrence of this text is replaced; nullptr: the whole file
  const char* until;  // nullptr: just `begin`; "\n": up to the end of the line; "$": to the
                      // end of the file; else: up to and including this text
  std::string replacement;
  bool may_warn = false;  // a valid but degenerate file: a warning naming it is fine too
};

std::string path_of(const DamagedRecording& d, Which w) {
  switch (w) {
    case Which::kRig:
      return d.rec() + "/rig.yaml";
    case Which::kFrames:
      return d.rec() + "/frames.csv";
    case Which::kTargets:
      return d.targets();
    case Which::kModel:
      return d.model();
  }
  return {};
}

std::string binary_garbage() {
  std::string s;
  for (int i = 0; i < 3000; ++i) s += static_cast<char>((i * 7919 + 13) & 0xFF);
  return s;
}

const FileDamage kDamages[] = {
    // rig.yaml
    {"rig_empty", Which::kRig, nullptr, nullptr, ""},
    {"rig_only_comment", Which::kRig, nullptr, nullptr, "# nothing here\n"},
    {"rig_unclosed_list", Which::kRig, "R: [", nullptr, "R: [[1, "},
    {"rig_tab_indent", Which::kRig, "\n  - name", nullptr, "\n\t- name"},
    {"rig_not_a_map", Which::kRig, nullptr, nullptr, "- 1\n- 2\n"},
    {"rig_binary", Which::kRig, nullptr, nullptr, binary_garbage()},
    {"rig_deep_nesting", Which::kRig, nullptr, nullptr, "cameras: " + std::string(50000, '[')},
    {"rig_fx_nan", Which::kRig, "fx: ", "\n", "fx: .nan"},
    {"rig_fx_inf", Which::kRig, "fx: ", "\n", "fx: .inf"},
    {"rig_fx_overflow", Which::kRig, "fx: ", "\n", "fx: 1e999"},
    {"rig_fx_negative", Which::kRig, "fx: ", "\n", "fx: -1290"},
    {"rig_cx_nan_text", Which::kRig, "cx: ", "\n", "cx: NaN"},
    {"rig_t_inf", Which::kRig, "t: [", "]", "t: [0, -.inf, 0]"},
    {"rig_R_nan", Which::kRig, "R: [", ",", "R: [nan,"},
    {"rig_R_singular", Which::kRig, "R: [", "]", "R: [1, 0, 0, 0, 1, 0, 0, 0, 0]"},
    {"rig_R_short", Which::kRig, "R: [", "]", "R: [1, 0, 0]"},
    {"rig_distortion_short", Which::kRig, "distortion: [", "]", "distortion: [0, 0]"},
    {"rig_distortion_nan", Which::kRig, "distortion: [", "]", "distortion: [0, .nan, 0, 0, 0]"},
    {"rig_width_zero", Which::kRig, "width: ", "\n", "width: 0"},
    {"rig_width_huge", Which::kRig, "width: ", "\n", "width: 99999999999999999999999"},
    {"rig_width_text", Which::kRig, "width: ", "\n", "width: wide"},
    {"rig_duplicate_key", Which::kRig, "width: ", "\n", "width: 1032\n    width: 1032"},
    {"rig_duplicate_camera", Which::kRig, "name: cam1", nullptr, "name: cam0"},
    {"rig_no_cameras", Which::kRig, nullptr, nullptr, "cameras: []\n"},
    {"rig_one_camera", Which::kRig, "\n  - name: cam1", "$", "\n"},
    {"rig_camera_path", Which::kRig, "name: cam1", nullptr, "name: ../../etc"},
    // frames.csv
    {"frames_empty", Which::kFrames, nullptr, nullptr, ""},
    {"frames_header_only", Which::kFrames, nullptr, nullptr, "frame,timestamp_ns\n"},
    {"frames_wrong_header", Which::kFrames, nullptr, nullptr, "frame;timestamp\n0;1\n"},
    {"frames_nan_timestamp", Which::kFrames, "\n1,", "\n", "\n1,nan"},
    {"frames_float_frame", Which::kFrames, "\n1,", nullptr, "\n1.5,"},
    {"frames_decreasing", Which::kFrames, "\n2,", nullptr, "\n0,"},
    {"frames_huge_number", Which::kFrames, "\n2,", nullptr, "\n99999999999999999999999,"},
    {"frames_negative_time", Which::kFrames, "\n1,", "\n", "\n1,-5"},
    {"frames_short_row", Which::kFrames, "\n1,", "\n", "\n1"},
    {"frames_binary", Which::kFrames, nullptr, nullptr, "frame,timestamp_ns\n" + binary_garbage()},
    // targets.yaml
    {"targets_empty", Which::kTargets, nullptr, nullptr, ""},
    {"targets_unclosed", Which::kTargets, nullptr, nullptr,
     "bodies: [{name: a, markers: [[0, 0, 0]"},
    {"targets_marker_nan", Which::kTargets, "- [", "]", "- [.nan, 0, 0]"},
    {"targets_marker_inf", Which::kTargets, "- [", "]", "- [0, .Inf, 0]"},
    {"targets_marker_overflow", Which::kTargets, "- [", "]", "- [0, 0, 1e400]"},
    {"targets_marker_short", Which::kTargets, "- [", "]", "- [0, 0]"},
    {"targets_marker_map", Which::kTargets, "- [", "]", "- {x: 1}"},
    {"targets_no_bodies", Which::kTargets, nullptr, nullptr, "bodies: []\n"},
    {"targets_diameter_nan", Which::kTargets, nullptr, nullptr,
     "marker_diameter: .nan\nbodies: []\n"},
    {"targets_diameter_negative", Which::kTargets, "bodies:", nullptr,
     "marker_diameter: -3\nbodies:"},
    {"targets_markers_coincide", Which::kTargets, nullptr, nullptr,
     "bodies:\n  - name: a\n    markers: [[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]]\n", true},
    {"targets_binary", Which::kTargets, nullptr, nullptr, binary_garbage()},
    // model.yaml
    {"model_empty", Which::kModel, nullptr, nullptr, ""},
    {"model_center_nan", Which::kModel, "center_parent: [", "]", "center_parent: [.nan, 0, 0]"},
    {"model_center_inf", Which::kModel, "center_child: [", "]", "center_child: [0, 0, -.inf]"},
    {"model_axis_zero", Which::kModel, "axis_parent: [", "]", "axis_parent: [0, 0, 0]"},
    {"model_axis_nan", Which::kModel, "axis_child: [", "]", "axis_child: [nan, nan, nan]"},
    {"model_unknown_body", Which::kModel, "parent: ", "\n", "parent: tentacle"},
    {"model_bad_type", Which::kModel, "type: ", "\n", "type: prismatic"},
    {"model_no_center", Which::kModel, "\n    center_parent: [", "]", ""},
    {"model_self_joint", Which::kModel, "child: ", "\n", "child: torso"},
    {"model_unclosed", Which::kModel, "center_parent: [", nullptr, "center_parent: [[["},
    {"model_deep_nesting", Which::kModel, nullptr, nullptr, "joints: " + std::string(50000, '{')},
};

class DamagedFile : public ::testing::TestWithParam<FileDamage> {};

TEST_P(DamagedFile, EndsWithOneLineNamingTheFile) {
  const FileDamage& dmg = GetParam();
  DamagedRecording d(std::string("file_") + dmg.name);
  const std::string path = path_of(d, dmg.file);
  std::string text = test::read_file(path);
  if (dmg.begin == nullptr) {
    text = dmg.replacement;
  } else {
    const std::size_t at = text.find(dmg.begin);
    ASSERT_NE(at, std::string::npos) << "'" << dmg.begin << "' not in " << path;
    std::size_t end = at + std::string(dmg.begin).size();
    if (dmg.until != nullptr) {
      const std::string u = dmg.until;
      if (u == "$") {
        end = text.size();
      } else {
        const std::size_t f = text.find(u, end);
        ASSERT_NE(f, std::string::npos) << "'" << u << "' not in " << path;
        end = u == "\n" ? f : f + u.size();
      }
    }
    text.replace(at, end - at, dmg.replacement);
  }
  test::write_file(path, text);
  const test::RunResult r = d.track();
  if (dmg.may_warn && r.exit_code == 0) {
    EXPECT_TRUE(test::is_warned_success(r, path));
  } else {
    EXPECT_TRUE(test::is_one_line_error(r, path));
  }
}

INSTANTIATE_TEST_SUITE_P(Reliability, DamagedFile, ::testing::ValuesIn(kDamages),
                         [](const ::testing::TestParamInfo<FileDamage>& i) {
                           return std::string(i.param.name);
                         });

TEST(DamagedRecording, EndlessFileInPlaceOfAYamlIsAOneLineError) {
  // targets.yaml as a link to /dev/zero: the reader stops at its size bound instead of
  // growing until the process dies.
  DamagedRecording d("targets_dev_zero");
  const std::string path = path_of(d, Which::kTargets);
  std::filesystem::remove(path);
  std::filesystem::create_symlink("/dev/zero", path);
  const test::RunResult r = d.track();
  EXPECT_TRUE(test::is_one_line_error(r, path)) << r.output;
  EXPECT_NE(r.output.find("larger than"), std::string::npos) << r.output;
}

TEST(DamagedRecording, OutputFolderThatIsAFileIsAOneLineError) {
  DamagedRecording d("out_is_file");
  test::write_file(d.out(), "not a folder");
  EXPECT_TRUE(test::is_one_line_error(d.track(), d.out()));
}

}  // namespace
}  // namespace mocap
