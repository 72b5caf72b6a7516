// `mocap evaluate <kind> ...` (extension, docs/evaluation.md): the paper's error
// evaluation against the simulator's ground truth, computed by src/track/evaluation.h.
// Each kind prints Markdown table rows (with --header also the table header), the first
// column being --label (e.g. the seed), so that bench/evaluation/run_evaluation.sh can
// concatenate runs into docs/evaluation.md:
//   calibration --targets T --model M --true-model gt/model_true.yaml
//   distance    --poses OUT/poses.csv --segments gt/segments.csv          (Table 1A)
//   precision   --targets T --model M --poses OUT/poses.csv --angles OUT/angles.csv (1B)
//   angles      --truth REC/gt --angles OUT/angles.csv [--series errors.csv]
//   rates       --truth REC/gt --angles OUT/angles.csv [--poses OUT/poses.csv]
//               (joint rates and their sd, and with --poses the body velocities; last
//               row "all": every sample pooled)
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "app/command_registry.h"
#include "formats/csv_outputs.h"
#include "formats/joints_yaml.h"
#include "formats/targets_yaml.h"
#include "track/evaluation.h"
#include "track/rate_evaluation.h"
#include "track/truth.h"

namespace mocap::app {
namespace {

struct EvaluateArgs {
  std::string targets, model, true_model, poses, angles, segments, truth, series, label;
  bool header = false;
};

int run_calibration(const EvaluateArgs& a) {
  auto targets = load_targets(a.targets);
  if (!targets) return fail(targets.error().message);
  auto est = load_model(a.model, *targets);
  if (!est) return fail(est.error().message);
  auto truth = load_model(a.true_model, *targets);
  if (!truth) return fail(truth.error().message);
  auto errors = calibration_errors(*est, *truth);
  if (!errors) return fail(a.model + ": " + errors.error().message);
  if (a.header) {
    std::printf(
        "| run | joint | type | centre error, parent frame [mm] | centre error, child frame [mm] | "
        "axis direction error parent / child [deg] | axis position error parent / child [mm] |\n"
        "| --- | --- | --- | --- | --- | --- | --- |\n");
  }
  for (const CalibrationError& e : *errors) {
    if (e.type == JointType::kHinge) {
      std::printf("| %s | %s | hinge | %.3f | %.3f | %.4f / %.4f | %.3f / %.3f |\n",
                  a.label.c_str(), e.joint.c_str(), e.center_parent_mm, e.center_child_mm,
                  e.axis_parent_deg, e.axis_child_deg, e.axis_position_parent_mm,
                  e.axis_position_child_mm);
    } else {
      std::printf("| %s | %s | ball | %.3f | %.3f | - | - |\n", a.label.c_str(), e.joint.c_str(),
                  e.center_parent_mm, e.center_child_mm);
    }
  }
  return 0;
}

int run_distance(const EvaluateArgs& a) {
  auto poses = read_poses_csv(a.poses);
  if (!poses) return fail(poses.error().message);
  auto segments = read_segments_csv(a.segments);
  if (!segments) return fail(segments.error().message);
  const auto errors = distance_errors(*poses, *segments);
  if (a.header) {
    std::printf(
        "| run | target | moves measured | RMSE [mm] | mean error [mm] | max abs error [mm] | "
        "measured distances "
        "[mm] |\n| --- | --- | --- | --- | --- | --- | --- |\n");
  }
  for (const BodyDistanceError& e : errors) {
    std::string list;
    for (const DistancePair& p : e.pairs) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%s%.2f", list.empty() ? "" : ", ", p.measured_mm);
      list += buf;
    }
    std::printf("| %s | %s | %d of %zu | %.4f | %+.4f | %.4f | %s |\n", a.label.c_str(),
                e.body.c_str(), e.pairs_used, e.pairs.size(), e.rmse_mm, e.mean_error_mm,
                e.max_abs_error_mm, list.c_str());
  }
  return 0;
}

int run_precision(const EvaluateArgs& a) {
  auto targets = load_targets(a.targets);
  if (!targets) return fail(targets.error().message);
  auto model = load_model(a.model, *targets);
  if (!model) return fail(model.error().message);
  auto poses = read_poses_csv(a.poses);
  if (!poses) return fail(poses.error().message);
  auto angles = read_angles_csv(a.angles);
  if (!angles) return fail(angles.error().message);
  const auto prec = joint_precision(*model, *poses, *angles);
  if (a.header) {
    std::printf(
        "| run | joint | frames | transformation std [mm] | rotation std [deg] | joint angle std "
        "[deg] |\n"
        "| --- | --- | --- | --- | --- | --- |\n");
  }
  for (const JointPrecision& p : prec) {
    std::printf("| %s | %s | %lld | %.4f | %.4f | %.4f |\n", a.label.c_str(), p.joint.c_str(),
                static_cast<long long>(p.frames), p.translation_std_mm, p.rotation_std_deg,
                p.angle_std_deg);
  }
  return 0;
}

int run_angles(const EvaluateArgs& a) {
  auto truth = load_ground_truth(a.truth);
  if (!truth) return fail(truth.error().message);
  auto angles = read_angles_csv(a.angles);
  if (!angles) return fail(angles.error().message);
  std::vector<AngleErrorSample> series;
  const auto errors = angle_errors(truth->angles, *angles, a.series.empty() ? nullptr : &series);
  if (!a.series.empty()) {
    std::FILE* f = std::fopen(a.series.c_str(), "w");
    if (!f) return fail(a.series + ": cannot open for writing");
    std::fprintf(f, "frame,time_s,joint,error_deg\n");
    for (const AngleErrorSample& s : series) {
      std::fprintf(f, "%lld,%.4f,%s,%.6f\n", static_cast<long long>(s.frame),
                   static_cast<double>(s.timestamp_ns) * 1e-9, s.joint.c_str(), s.error_deg);
    }
    if (std::fclose(f) != 0) return fail(a.series + ": write failed");
  }
  if (a.header) {
    std::printf(
        "| run | joint | frames | RMS error [deg] | max [deg] | mean (hinge: bias) [deg] | RMS "
        "without the "
        "bias [deg] | frames > 1 deg | RMS of the others [deg] |\n"
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  }
  for (const JointAngleError& e : errors) {
    std::printf("| %s | %s | %lld | %.4f | %.4f | %+.4f | %.4f | %lld | %.4f |\n", a.label.c_str(),
                e.joint.c_str(), static_cast<long long>(e.frames), e.rms_deg, e.max_deg, e.mean_deg,
                e.rms_debiased_deg, static_cast<long long>(e.gross), e.rms_without_gross_deg);
  }
  return 0;
}

int run_rates(const EvaluateArgs& a) {
  auto truth = load_ground_truth(a.truth);
  if (!truth) return fail(truth.error().message);
  auto angles = read_angles_csv(a.angles);
  if (!angles) return fail(angles.error().message);
  JointRateError all;
  const auto errors = rate_errors(truth->angles, *angles, &all);
  if (all.samples == 0)
    return fail(a.angles + ": no rates (columns da0..sd_da2) at frames of the ground truth");
  if (a.header) {
    std::printf(
        "| run | joint | samples | RMS rate error [deg/s] | max [deg/s] | RMS stated sd [deg/s] | "
        "sd / RMS |\n| --- | --- | --- | --- | --- | --- | --- |\n");
  }
  std::vector<JointRateError> rows = errors;
  rows.push_back(all);  // the last row: every sample pooled
  for (const JointRateError& r : rows) {
    std::printf("| %s | %s | %lld | %.3f | %.3f | %.3f | %.2f |\n", a.label.c_str(),
                r.joint.c_str(), static_cast<long long>(r.samples), r.rms_deg_s, r.max_deg_s,
                r.rms_sd_deg_s, r.sd_ratio);
  }
  if (a.poses.empty()) return 0;
  // Body velocities (poses.csv vx..sd_wz), when asked for.
  auto poses = read_poses_csv(a.poses);
  if (!poses) return fail(poses.error().message);
  BodyRateError pooled;
  std::vector<BodyRateError> bodies = body_rate_errors(truth->poses, *poses, &pooled);
  if (pooled.linear_mm_s.samples == 0)
    return fail(a.poses + ": no body velocities (columns vx..sd_wz) at frames of the ground truth");
  bodies.push_back(pooled);
  std::printf(
      "\n| run | body | samples | RMS velocity error [mm/s] | max [mm/s] | RMS stated sd [mm/s] | "
      "sd / RMS | RMS angular velocity error [deg/s] | max [deg/s] | RMS stated sd [deg/s] | "
      "sd / RMS |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  for (const BodyRateError& r : bodies) {
    const RateStats& v = r.linear_mm_s;
    const RateStats& w = r.angular_deg_s;
    std::printf("| %s | %s | %lld | %.2f | %.2f | %.2f | %.2f | %.3f | %.3f | %.3f | %.2f |\n",
                a.label.c_str(), r.body.c_str(), static_cast<long long>(v.samples), v.rms, v.max,
                v.rms_sd, v.sd_ratio, w.rms, w.max, w.rms_sd, w.sd_ratio);
  }
  return 0;
}

void register_evaluate(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<EvaluateArgs>();
  CLI::App* cmd =
      app.add_subcommand("evaluate", "(extension) Error evaluation against simulator ground truth");
  cmd->require_subcommand(1);
  auto common = [&](CLI::App* sub) {
    sub->add_option("--label", args->label, "First column of every row (e.g. the seed)");
    sub->add_flag("--header", args->header, "Also print the Markdown table header");
  };
  CLI::App* cal = cmd->add_subcommand("calibration", "Joint model errors against the true model");
  cal->add_option("--targets", args->targets, "targets.yaml")->required();
  cal->add_option("--model", args->model, "Estimated model.yaml")->required();
  cal->add_option("--true-model", args->true_model, "True model (gt/model_true.yaml)")->required();
  common(cal);
  cal->callback([args, &exit_code] { exit_code = run_calibration(*args); });
  CLI::App* dist =
      cmd->add_subcommand("distance", "Table 1A: measured vs known translation per target");
  dist->add_option("--poses", args->poses, "Tracked poses.csv")->required();
  dist->add_option("--segments", args->segments, "gt/segments.csv")->required();
  common(dist);
  dist->callback([args, &exit_code] { exit_code = run_distance(*args); });
  CLI::App* prec = cmd->add_subcommand("precision", "Table 1B: standard deviations per joint");
  prec->add_option("--targets", args->targets, "targets.yaml")->required();
  prec->add_option("--model", args->model, "model.yaml used for tracking")->required();
  prec->add_option("--poses", args->poses, "Tracked poses.csv")->required();
  prec->add_option("--angles", args->angles, "Tracked angles.csv")->required();
  common(prec);
  prec->callback([args, &exit_code] { exit_code = run_precision(*args); });
  CLI::App* ang = cmd->add_subcommand("angles", "Joint-angle errors against ground truth");
  ang->add_option("--truth", args->truth, "Ground-truth folder (REC/gt)")->required();
  ang->add_option("--angles", args->angles, "Tracked angles.csv")->required();
  ang->add_option("--series", args->series,
                  "Write per-frame errors (frame,time_s,joint,error_deg)");
  common(ang);
  ang->callback([args, &exit_code] { exit_code = run_angles(*args); });
  CLI::App* rates = cmd->add_subcommand(
      "rates", "Joint-rate errors (angles.csv da0..da2) and their stated sd against ground truth");
  rates->add_option("--truth", args->truth, "Ground-truth folder (REC/gt)")->required();
  rates->add_option("--angles", args->angles, "Tracked angles.csv")->required();
  rates->add_option("--poses", args->poses,
                    "Tracked poses.csv: also the body velocities (vx..sd_wz) against the truth");
  common(rates);
  rates->callback([args, &exit_code] { exit_code = run_rates(*args); });
}

const CommandRegistrar kEvaluateRegistrar(80, register_evaluate);

}  // namespace
}  // namespace mocap::app
