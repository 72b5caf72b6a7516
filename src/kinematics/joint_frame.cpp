// Design: see joint_frame.h. Pure function, noexcept, no allocation (used at set-up by
// the angle solver and the URDF writer, and by the refinement's initialisation).
#include "kinematics/joint_frame.h"

#include <cmath>

namespace mocap::kinematics {

HingeFrame make_hinge_frame(const Vec3& c, const Vec3& axis) noexcept {
  HingeFrame out;
  const Vec3 cz = axis.normalized();
  Vec3 cy = c.cross(cz);
  if (cy.norm() < kMinLeverMm) {
    // Fallback: the basis axis least aligned with c_z gives a well-defined c_y.
    Eigen::Index k = 0;
    cz.cwiseAbs().minCoeff(&k);
    cy = Vec3::Unit(k).cross(cz);
    out.degenerate = true;
  }
  cy.normalize();
  const Vec3 cx = cy.cross(cz);
  Mat3 R;
  R.col(0) = cx;
  R.col(1) = cy;
  R.col(2) = cz;
  out.T_body_joint = make_iso(R, c);
  return out;
}

}  // namespace mocap::kinematics
