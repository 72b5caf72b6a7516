// Design: see refinement.h. One DynamicAutoDiffCostFunction per marker observation: the
// parameter blocks are the root pose of the frame and, for every joint on the path from
// the root to the marker's body, its per-frame block followed by its global blocks. All
// parameter memory is allocated before the first block is added (Ceres keeps pointers).
#include "kinematics/refinement.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include "core/rotation.h"
#include "core/units.h"
#include "kinematics/joint_frame.h"

namespace mocap::kinematics {
namespace {

struct HingeConst {
  Vec3 ref_parent, ref_child;  // fixed reference vectors of F_p, F_c
  Vec3 c_child0;
  Eigen::Matrix<double, 3, 2> B;  // c_child = c_child0 + B u
};

struct JointParams {  // global parameters of one joint
  JointType type = JointType::kBall;
  double c_p[3] = {0, 0, 0};
  double c_c[3] = {0, 0, 0};  // ball only
  double a_p[3] = {0, 0, 1};  // hinge only
  double a_c[3] = {0, 0, 1};
  double u[2] = {0, 0};
  HingeConst k;
};

template <class T>
using V3 = Eigen::Matrix<T, 3, 1>;

// F^T v and F w for F = [x y a], x = ref orthogonalised against a.
template <class T>
void hinge_basis(const T* a_raw, const Vec3& ref, V3<T>& x, V3<T>& y, V3<T>& a) {
  a = V3<T>(a_raw[0], a_raw[1], a_raw[2]).normalized();
  const V3<T> r = ref.cast<T>();
  x = (r - r.dot(a) * a).normalized();
  y = a.cross(x);
}

struct MarkerResidual {
  struct Step {
    const JointParams* joint;
    int first_block;  // index of its per-frame block
  };
  std::vector<Step> steps;  // root -> body order
  Vec3 X_body, X_meas;

  template <class T>
  bool operator()(T const* const* p, T* residual) const {
    V3<T> X = X_body.cast<T>();
    for (auto it = steps.rbegin(); it != steps.rend(); ++it) {
      const int b = it->first_block;
      const JointParams& jp = *it->joint;
      if (jp.type == JointType::kBall) {
        const T* q = p[b];
        const T* c_p = p[b + 1];
        const T* c_c = p[b + 2];
        const T v[3] = {X[0] - c_c[0], X[1] - c_c[1], X[2] - c_c[2]};
        T w[3];
        ceres::QuaternionRotatePoint(q, v, w);
        X = V3<T>(w[0] + c_p[0], w[1] + c_p[1], w[2] + c_p[2]);
      } else {
        const T theta = p[b][0];
        const T* a_p = p[b + 1];
        const T* c_p = p[b + 2];
        const T* a_c = p[b + 3];
        const T* u = p[b + 4];
        const V3<T> c_c =
            jp.k.c_child0.cast<T>() + jp.k.B.cast<T>() * Eigen::Matrix<T, 2, 1>(u[0], u[1]);
        V3<T> xc, yc, ac, xp, yp, ap;
        hinge_basis(a_c, jp.k.ref_child, xc, yc, ac);
        hinge_basis(a_p, jp.k.ref_parent, xp, yp, ap);
        const V3<T> v = X - c_c;
        const T w0 = xc.dot(v), w1 = yc.dot(v), w2 = ac.dot(v);
        const T ct = cos(theta), st = sin(theta);
        X = xp * (ct * w0 - st * w1) + yp * (st * w0 + ct * w1) + ap * w2 +
            V3<T>(c_p[0], c_p[1], c_p[2]);
      }
    }
    const T x[3] = {X[0], X[1], X[2]};
    T w[3];
    ceres::QuaternionRotatePoint(p[0], x, w);
    for (int i = 0; i < 3; ++i) residual[i] = w[i] + p[1][i] - T(X_meas[i]);
    return true;
  }
};

int frame_block_size(JointType t) { return t == JointType::kBall ? 4 : 1; }

void set_quat(double* q, const Mat3& R) {
  const Quat e = canonical_quat(R);
  q[0] = e.w();
  q[1] = e.x();
  q[2] = e.y();
  q[3] = e.z();
}

// Square root of the largest eigenvalue of a symmetric covariance.
double max_std(const Mat3& C) {
  const Mat3 S = 0.5 * (C + C.transpose());
  return std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Mat3>(S).eigenvalues().maxCoeff()));
}

std::string num4(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.4g", v);
  return buf;
}

}  // namespace

Expected<RefinementOutput> refine_joints(const TargetSet& targets, const JointModel& initial,
                                         const KinematicTree& tree, const CalibrationInput& input,
                                         const std::vector<int>& frames,
                                         const CalibrationOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t nb = targets.bodies.size();
  const std::size_t nj = initial.joints.size();
  const std::size_t nf = frames.size();

  // Global parameters.
  std::vector<JointParams> jp(nj);
  for (std::size_t j = 0; j < nj; ++j) {
    const JointSpec& s = initial.joints[j];
    JointParams& g = jp[j];
    g.type = s.type;
    Eigen::Map<Vec3>(g.c_p) = s.center_parent;
    Eigen::Map<Vec3>(g.c_c) = s.center_child;
    if (s.type == JointType::kHinge) {
      Eigen::Map<Vec3>(g.a_p) = s.axis_parent.normalized();
      Eigen::Map<Vec3>(g.a_c) = s.axis_child.normalized();
      const Iso3 Cp = make_hinge_frame(s.center_parent, s.axis_parent).T_body_joint;
      const Iso3 Cc = make_hinge_frame(s.center_child, s.axis_child).T_body_joint;
      g.k.ref_parent = Cp.linear().col(0);
      g.k.ref_child = Cc.linear().col(0);
      g.k.c_child0 = s.center_child;
      g.k.B = Cc.linear().leftCols<2>();
    }
  }

  // Which bodies are usable in which frame: found, with markers, ancestors usable.
  std::vector<std::vector<char>> active(nf, std::vector<char>(nb, 0));
  for (std::size_t f = 0; f < nf; ++f) {
    const CalibrationFrame& fr = input.frames[static_cast<std::size_t>(frames[f])];
    for (int r : tree.roots) {
      const auto& o = fr.bodies[static_cast<std::size_t>(r)];
      active[f][static_cast<std::size_t>(r)] = o.found && !o.markers.empty();
    }
    for (int j : tree.joint_order) {
      const JointSpec& s = initial.joints[static_cast<std::size_t>(j)];
      const auto& o = fr.bodies[static_cast<std::size_t>(s.child_index)];
      active[f][static_cast<std::size_t>(s.child_index)] =
          active[f][static_cast<std::size_t>(s.parent_index)] && o.found && !o.markers.empty();
    }
  }

  // Per-frame parameters: [root q(4) t(3)] per body slot, [ball q(4) | theta(1)] per joint.
  const std::size_t stride_body = 7, stride_joint = 4;
  std::vector<double> frame_params(nf * (nb * stride_body + nj * stride_joint), 0.0);
  auto body_block = [&](std::size_t f, std::size_t b) {
    return frame_params.data() + f * (nb * stride_body + nj * stride_joint) + b * stride_body;
  };
  auto joint_block = [&](std::size_t f, std::size_t j) {
    return frame_params.data() + f * (nb * stride_body + nj * stride_joint) + nb * stride_body +
           j * stride_joint;
  };

  ceres::Problem::Options popts;
  ceres::Problem problem(popts);
  auto* quat_manifold = new ceres::QuaternionManifold;
  auto* sphere_manifold = new ceres::SphereManifold<3>;
  bool quat_used = false, sphere_used = false;
  auto* loss = new ceres::HuberLoss(options.huber_mm);

  for (std::size_t j = 0; j < nj; ++j) {
    JointParams& g = jp[j];
    problem.AddParameterBlock(g.c_p, 3);
    if (g.type == JointType::kBall) {
      problem.AddParameterBlock(g.c_c, 3);
    } else {
      problem.AddParameterBlock(g.a_p, 3, sphere_manifold);
      problem.AddParameterBlock(g.a_c, 3, sphere_manifold);
      problem.AddParameterBlock(g.u, 2);
      sphere_used = true;
    }
  }

  int n_tangent = 0;
  for (const auto& g : jp) n_tangent += g.type == JointType::kBall ? 6 : 9;

  struct BlockInfo {
    ceres::ResidualBlockId id;
    int body;
  };
  std::vector<BlockInfo> blocks;
  for (std::size_t f = 0; f < nf; ++f) {
    const CalibrationFrame& fr = input.frames[static_cast<std::size_t>(frames[f])];
    for (int r : tree.roots) {
      if (!active[f][static_cast<std::size_t>(r)]) continue;
      double* rb = body_block(f, static_cast<std::size_t>(r));
      const Iso3& T = fr.bodies[static_cast<std::size_t>(r)].T_world_body;
      set_quat(rb, T.linear());
      Eigen::Map<Vec3>(rb + 4) = T.translation();
      problem.AddParameterBlock(rb, 4, quat_manifold);
      problem.AddParameterBlock(rb + 4, 3);
      quat_used = true;
      n_tangent += 6;
    }
    for (int j : tree.joint_order) {
      const JointSpec& s = initial.joints[static_cast<std::size_t>(j)];
      if (!active[f][static_cast<std::size_t>(s.child_index)]) continue;
      double* q = joint_block(f, static_cast<std::size_t>(j));
      const RelativePose rel =
          relative_pose(fr.bodies[static_cast<std::size_t>(s.parent_index)].T_world_body,
                        fr.bodies[static_cast<std::size_t>(s.child_index)].T_world_body);
      if (s.type == JointType::kBall) {
        set_quat(q, rel.R_parent_child);
        problem.AddParameterBlock(q, 4, quat_manifold);
        n_tangent += 3;
      } else {
        const JointParams& g = jp[static_cast<std::size_t>(j)];
        Mat3 Fp, Fc;
        Fp << g.k.ref_parent, Eigen::Map<const Vec3>(g.a_p).cross(g.k.ref_parent),
            Eigen::Map<const Vec3>(g.a_p);
        Fc << g.k.ref_child, Eigen::Map<const Vec3>(g.a_c).cross(g.k.ref_child),
            Eigen::Map<const Vec3>(g.a_c);
        const Mat3 M = Fp.transpose() * rel.R_parent_child * Fc;
        q[0] = std::atan2(M(1, 0) - M(0, 1), M(0, 0) + M(1, 1));
        problem.AddParameterBlock(q, 1);
        n_tangent += 1;
      }
    }
    // Residuals of every active body.
    for (std::size_t b = 0; b < nb; ++b) {
      if (!active[f][b]) continue;
      const int root = tree.root_of(static_cast<int>(b));
      const std::vector<int> path = tree.path_to(initial, static_cast<int>(b));
      std::vector<double*> params = {body_block(f, static_cast<std::size_t>(root)),
                                     body_block(f, static_cast<std::size_t>(root)) + 4};
      std::vector<int> sizes = {4, 3};
      std::vector<MarkerResidual::Step> steps;
      for (int j : path) {
        JointParams& g = jp[static_cast<std::size_t>(j)];
        steps.push_back({&g, static_cast<int>(params.size())});
        params.push_back(joint_block(f, static_cast<std::size_t>(j)));
        sizes.push_back(frame_block_size(g.type));
        if (g.type == JointType::kBall) {
          params.insert(params.end(), {g.c_p, g.c_c});
          sizes.insert(sizes.end(), {3, 3});
        } else {
          params.insert(params.end(), {g.a_p, g.c_p, g.a_c, g.u});
          sizes.insert(sizes.end(), {3, 3, 3, 2});
        }
      }
      const auto& obs = fr.bodies[b];
      for (const MarkerObservation& m : obs.markers) {
        auto* functor = new MarkerResidual;
        functor->steps = steps;
        functor->X_body = targets.bodies[b].markers_body[static_cast<std::size_t>(m.marker_index)];
        functor->X_meas = m.X_world_mm;
        auto* cost = new ceres::DynamicAutoDiffCostFunction<MarkerResidual, 8>(functor);
        for (int sz : sizes) cost->AddParameterBlock(sz);
        cost->SetNumResiduals(3);
        blocks.push_back({problem.AddResidualBlock(cost, loss, params), static_cast<int>(b)});
      }
    }
  }
  if (!quat_used) delete quat_manifold;
  if (!sphere_used) delete sphere_manifold;
  if (blocks.empty()) {
    delete loss;
    return Error{"calibration: refinement: no marker observations"};
  }

  ceres::Solver::Options sopts;
  sopts.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  sopts.max_num_iterations = options.max_iterations;
  sopts.function_tolerance = 1e-10;
  sopts.parameter_tolerance = 1e-10;
  sopts.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(sopts, &problem, &summary);
  if (!summary.IsSolutionUsable()) {
    return Error{"calibration: refinement failed: " + summary.message};
  }

  RefinementOutput out;
  out.model = initial;
  out.frames = static_cast<int>(nf);
  out.iterations = static_cast<int>(summary.iterations.size());
  out.summary = summary.BriefReport();
  if (summary.termination_type != ceres::CONVERGENCE) {
    out.warnings.push_back("calibration: refinement did not converge: " + summary.message);
  }

  // Residuals without the loss function, per body.
  ceres::Problem::EvaluateOptions eopts;
  eopts.apply_loss_function = false;
  for (const auto& bi : blocks) eopts.residual_blocks.push_back(bi.id);
  std::vector<double> res;
  problem.Evaluate(eopts, nullptr, &res, nullptr, nullptr);
  std::vector<double> sum2(nb, 0.0), maxr(nb, 0.0);
  std::vector<int> count(nb, 0);
  double total2 = 0.0;
  int outliers = 0;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const double r2 =
        res[3 * i] * res[3 * i] + res[3 * i + 1] * res[3 * i + 1] + res[3 * i + 2] * res[3 * i + 2];
    const auto b = static_cast<std::size_t>(blocks[i].body);
    sum2[b] += r2;
    total2 += r2;
    maxr[b] = std::max(maxr[b], std::sqrt(r2));
    ++count[b];
    if (std::sqrt(r2) > 3.0 * options.huber_mm) ++outliers;
  }
  for (std::size_t b = 0; b < nb; ++b) {
    if (count[b] == 0) continue;
    out.bodies.push_back(
        {targets.bodies[b].name, count[b], std::sqrt(sum2[b] / count[b]), maxr[b]});
  }
  if (outliers * 100 > static_cast<int>(blocks.size())) {
    out.warnings.push_back("calibration: " + std::to_string(outliers) + " of " +
                           std::to_string(blocks.size()) + " marker residuals exceed " +
                           num4(3.0 * options.huber_mm) + " mm (outliers or a wrong joint type)");
  }

  // Refined parameters back into the model.
  out.joint_rms_mm.assign(nj, 0.0);
  for (std::size_t j = 0; j < nj; ++j) {
    JointSpec& s = out.model.joints[j];
    const JointParams& g = jp[j];
    const auto cb = static_cast<std::size_t>(s.child_index);
    out.joint_rms_mm[j] = count[cb] ? std::sqrt(sum2[cb] / count[cb]) : 0.0;
    s.center_parent = Eigen::Map<const Vec3>(g.c_p);
    if (g.type == JointType::kBall) {
      s.center_child = Eigen::Map<const Vec3>(g.c_c);
    } else {
      s.axis_parent = Eigen::Map<const Vec3>(g.a_p).normalized();
      s.axis_child = Eigen::Map<const Vec3>(g.a_c).normalized();
      s.center_child = g.k.c_child0 + g.k.B * Eigen::Map<const Eigen::Vector2d>(g.u);
      const double slide =
          -(s.center_parent.dot(s.axis_parent) + s.center_child.dot(s.axis_child)) / 2.0;
      s.center_parent += slide * s.axis_parent;
      s.center_child += slide * s.axis_child;
    }
    s.calibrated = true;
  }

  // Covariance of the joint parameters.
  if (options.covariance) {
    const int m = static_cast<int>(3 * blocks.size());
    const double dof = static_cast<double>(m - n_tangent);
    const double sigma2 = dof > 0 ? total2 / dof : 0.0;
    ceres::Covariance::Options copts;
    copts.algorithm_type = ceres::SPARSE_QR;
    ceres::Covariance cov(copts);
    std::vector<std::pair<const double*, const double*>> pairs;
    for (const auto& g : jp) {
      pairs.emplace_back(g.c_p, g.c_p);
      if (g.type == JointType::kBall) {
        pairs.emplace_back(g.c_c, g.c_c);
      } else {
        pairs.emplace_back(g.a_p, g.a_p);
        pairs.emplace_back(g.a_c, g.a_c);
      }
    }
    if (!cov.Compute(pairs, &problem)) {
      out.warnings.push_back(
          "calibration: covariance not computed (rank-deficient Jacobian: a parameter is not "
          "determined by the data); no uncertainties written");
    } else {
      for (std::size_t j = 0; j < nj; ++j) {
        JointSpec& s = out.model.joints[j];
        const JointParams& g = jp[j];
        Mat3 Cp;
        cov.GetCovarianceBlock(g.c_p, g.c_p, Cp.data());
        Cp *= sigma2;
        if (g.type == JointType::kBall) {
          Mat3 Cc;
          cov.GetCovarianceBlock(g.c_c, g.c_c, Cc.data());
          Cc *= sigma2;
          const Vec3 sp = Cp.diagonal().cwiseMax(0.0).cwiseSqrt();
          const Vec3 sc = Cc.diagonal().cwiseMax(0.0).cwiseSqrt();
          s.set_extra("center_parent_std_mm", std::vector<double>{sp[0], sp[1], sp[2]});
          s.set_extra("center_child_std_mm", std::vector<double>{sc[0], sc[1], sc[2]});
        } else {
          // Ambient 3x3 covariance of the unit axis (the manifold's Plus Jacobian maps the
          // tangent covariance); for a unit vector its largest eigenvalue is the variance
          // of the direction angle in rad^2, independent of the tangent's scaling.
          Mat3 Ap, Ac;
          cov.GetCovarianceBlock(g.a_p, g.a_p, Ap.data());
          cov.GetCovarianceBlock(g.a_c, g.a_c, Ac.data());
          const double ap_deg = max_std(sigma2 * Ap) * kDegPerRad;
          const double ac_deg = max_std(sigma2 * Ac) * kDegPerRad;
          const Mat3 P = Mat3::Identity() - s.axis_parent * s.axis_parent.transpose();
          const Mat3 Cperp = P * Cp * P;
          const double pos_mm = max_std(Cperp);
          s.set_extra("axis_parent_std_deg", std::vector<double>{ap_deg});
          s.set_extra("axis_child_std_deg", std::vector<double>{ac_deg});
          s.set_extra("axis_position_std_mm", std::vector<double>{pos_mm});
        }
      }
    }
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace mocap::kinematics
