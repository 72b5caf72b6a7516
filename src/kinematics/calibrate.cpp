// Design: see calibrate.h. Validation first (one-line errors naming frame/body/marker),
// then per-joint linear estimates, then the joint refinement of the whole forest.
#include "kinematics/calibrate.h"

#include <algorithm>
#include <cstdio>

#include "core/rotation.h"
#include "kinematics/joint_frame.h"
#include "kinematics/kinematic_tree.h"
#include "kinematics/refinement.h"

namespace mocap::kinematics {
namespace {

std::string num3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3g", v);
  return buf;
}

std::string label_of(const JointSpec& s) {
  return "calibration: joint '" + s.name + "' (" + joint_type_name(s.type) + ")";
}

Expected<void> validate(const TargetSet& targets, const CalibrationInput& input) {
  const std::size_t nb = targets.bodies.size();
  if (input.frames.empty()) return Error{"calibration input: no frames"};
  for (std::size_t f = 0; f < input.frames.size(); ++f) {
    const auto& fr = input.frames[f];
    const std::string wf = "calibration input: frames[" + std::to_string(f) + "]";
    if (fr.bodies.size() != nb) {
      return Error{wf + ": " + std::to_string(fr.bodies.size()) + " bodies, targets have " +
                   std::to_string(nb)};
    }
    for (std::size_t b = 0; b < nb; ++b) {
      const auto& o = fr.bodies[b];
      if (!o.found) continue;
      const std::string wb =
          wf + ".bodies[" + std::to_string(b) + "] ('" + targets.bodies[b].name + "')";
      if (!o.T_world_body.matrix().allFinite() || !is_rotation(o.T_world_body.linear(), 1e-6)) {
        return Error{wb + ": T_world_body is not a finite rigid transform"};
      }
      for (std::size_t m = 0; m < o.markers.size(); ++m) {
        const auto& mk = o.markers[m];
        if (mk.marker_index < 0 ||
            mk.marker_index >= static_cast<int>(targets.bodies[b].markers_body.size())) {
          return Error{wb + ".markers[" + std::to_string(m) + "]: marker index " +
                       std::to_string(mk.marker_index) + " out of range (target has " +
                       std::to_string(targets.bodies[b].markers_body.size()) + ")"};
        }
        if (!mk.X_world_mm.allFinite()) {
          return Error{wb + ".markers[" + std::to_string(m) + "]: non-finite position"};
        }
      }
    }
  }
  return {};
}

void check_lever(const JointSpec& s, const CalibrationOptions& options,
                 std::vector<std::string>& warnings) {
  if (s.type != JointType::kHinge) return;
  const double lp = s.center_parent.cross(s.axis_parent).norm();
  const double lc = s.center_child.cross(s.axis_child).norm();
  if (std::min(lp, lc) < options.min_axis_lever_mm) {
    warnings.push_back(label_of(s) + ": the axis passes " + num3(std::min(lp, lc)) +
                       " mm from a body origin (< " + num3(options.min_axis_lever_mm) +
                       " mm): the zero of the hinge angle (frame C) is poorly defined");
  }
}

}  // namespace

Expected<CalibrationResult> calibrate_joints(const TargetSet& targets, const JointModel& topology,
                                             const CalibrationInput& input,
                                             const CalibrationOptions& options) {
  auto tree = build_tree(topology, targets.bodies.size());
  if (!tree) return tree.error();
  if (auto v = validate(targets, input); !v) return v.error();

  CalibrationResult result;
  result.model = topology;
  auto& report = result.report;

  // 1. Linear estimates per joint.
  for (auto& s : result.model.joints) {
    std::vector<RelativePose> rel;
    for (const auto& fr : input.frames) {
      const auto& p = fr.bodies[static_cast<std::size_t>(s.parent_index)];
      const auto& c = fr.bodies[static_cast<std::size_t>(s.child_index)];
      if (p.found && c.found) rel.push_back(relative_pose(p.T_world_body, c.T_world_body));
    }
    JointReport jr;
    jr.joint = s.name;
    jr.frames_used = static_cast<int>(rel.size());
    if (s.type == JointType::kBall) {
      auto est = estimate_ball(rel, options.linear, label_of(s));
      if (!est) return est.error();
      s.center_parent = est->center_parent;
      s.center_child = est->center_child;
      jr.linear = est->diagnostics;
    } else {
      const Vec3 hint = s.axis_parent.norm() > 0 ? s.axis_parent : Vec3::UnitZ();
      auto est = estimate_hinge(rel, options.linear, label_of(s), hint);
      if (!est) return est.error();
      s.center_parent = est->center_parent;
      s.center_child = est->center_child;
      s.axis_parent = est->axis_parent;
      s.axis_child = est->axis_child;
      jr.linear = est->diagnostics;
    }
    s.calibrated = true;
    s.set_extra("frames_used", {static_cast<double>(jr.frames_used)});
    s.set_extra("linear_singular_values", std::vector<double>(jr.linear.singular_values.begin(),
                                                              jr.linear.singular_values.end()));
    s.set_extra("linear_residual_rms_mm", {jr.linear.residual_rms_mm});
    report.joints.push_back(jr);
  }

  // 2. Joint refinement on the marker residuals.
  if (options.refine) {
    std::vector<int> usable;
    for (std::size_t f = 0; f < input.frames.size(); ++f) {
      const auto& fr = input.frames[f];
      const bool any_root = std::any_of(tree->roots.begin(), tree->roots.end(), [&](int r) {
        return fr.bodies[static_cast<std::size_t>(r)].found;
      });
      if (any_root) usable.push_back(static_cast<int>(f));
    }
    std::vector<int> frames = usable;
    if (options.max_frames > 0 && static_cast<int>(usable.size()) > options.max_frames) {
      frames.clear();
      const double step = static_cast<double>(usable.size()) / options.max_frames;
      for (int i = 0; i < options.max_frames; ++i) {
        frames.push_back(usable[static_cast<std::size_t>(i * step)]);
      }
    }
    // Extras of the linear step are kept; covariance extras are appended by refine_joints.
    auto ref = refine_joints(targets, result.model, *tree, input, frames, options);
    if (!ref) return ref.error();
    result.model = std::move(ref->model);
    for (std::size_t j = 0; j < result.model.joints.size(); ++j) {
      report.joints[j].residual_rms_mm = ref->joint_rms_mm[j];
      result.model.joints[j].set_extra("residual_rms_mm", {ref->joint_rms_mm[j]});
    }
    report.bodies = std::move(ref->bodies);
    report.refine_frames = ref->frames;
    report.refine_iterations = ref->iterations;
    report.refine_seconds = ref->seconds;
    report.solver_summary = ref->summary;
    report.warnings.insert(report.warnings.end(), ref->warnings.begin(), ref->warnings.end());
  }
  for (const auto& s : result.model.joints) check_lever(s, options, report.warnings);
  return result;
}

std::string format_report(const CalibrationResult& result) {
  auto v3 = [](const Vec3& v) {
    return "[" + num3(v[0]) + ", " + num3(v[1]) + ", " + num3(v[2]) + "]";
  };
  std::string s;
  const auto& r = result.report;
  for (std::size_t j = 0; j < result.model.joints.size(); ++j) {
    const JointSpec& js = result.model.joints[j];
    s += "joint " + js.name + " (" + joint_type_name(js.type) + ", " + js.parent + " -> " +
         js.child + "): center_parent " + v3(js.center_parent) + " mm, center_child " +
         v3(js.center_child) + " mm";
    if (js.type == JointType::kHinge) {
      s += ", axis_parent " + v3(js.axis_parent) + ", axis_child " + v3(js.axis_child);
    }
    s += "\n";
    if (j < r.joints.size()) s += "  linear: " + r.joints[j].linear.describe() + "\n";
    for (const auto& [key, values] : js.extra) {
      if (key == "linear_singular_values") continue;
      s += "  " + key + ":";
      for (double x : values) s += " " + num3(x);
      s += "\n";
    }
  }
  for (const auto& b : r.bodies) {
    s += "body " + b.body + ": residual rms " + num3(b.rms_mm) + " mm, max " + num3(b.max_mm) +
         " mm over " + std::to_string(b.observations) + " markers\n";
  }
  if (r.refine_frames > 0) {
    s += "refinement: " + std::to_string(r.refine_frames) + " frames, " +
         std::to_string(r.refine_iterations) + " iterations, " + num3(r.refine_seconds) + " s\n";
  }
  for (const auto& w : r.warnings) s += "warning: " + w + "\n";
  return s;
}

}  // namespace mocap::kinematics
