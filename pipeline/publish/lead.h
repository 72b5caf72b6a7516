// Design: tracker-side latency compensation (outputs.udp[i].lead_ms, outputs.iceoryx
// lead_ms): the joint state a controller receives is the state predicted to the instant it
// is published plus a configured lead, not the state at the camera's trigger. The angles
// are extrapolated by the client library's own predict() (client/predict.h: the message's
// causal rates, sd grown with the rate's sd), so the tracker and a consumer predicting for
// itself agree exactly; each joint's quaternion is recomputed from its predicted angles
// (ball: the XYZ Euler angles; hinge: the measured quaternion turned by the angle's change
// about the hinge axis, which needs the calibrated model), and hinge angles stay
// continuous (unwrapped as the tracker publishes them). A predicted message is marked:
// flags bit kFlagPredicted and lead_us (the lead; the state's time is publish_ns +
// lead_us). Joints without known rates are published as measured. A message whose
// capture lies more than the horizon before publish + lead is not predicted at all (flag
// clear; counted by the caller). Setup validates; apply() is noexcept and allocation-free.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "client/joints_message.h"
#include "client/predict.h"
#include "core/expected.h"
#include "core/types.h"
#include "formats/joints_yaml.h"

namespace mocap::publish {

// The longest lead: the client library's prediction horizon.
inline constexpr double kMaxLeadMs = client::kDefaultPredictHorizonS * 1e3;

class LeadPredictor {
 public:
  // lead_ms in (0, kMaxLeadMs]; model: the joints of the messages (hinge axes), may be null
  // when no joints are published. `where` prefixes errors ("run.yaml: outputs.iceoryx").
  static Expected<LeadPredictor> create(double lead_ms, const JointModel* model,
                                        const std::string& where);

  // out = in predicted to in.publish_ns + lead. False: beyond the horizon, out = in.
  bool apply(const client::JointsMessage& in, client::JointsMessage& out) const noexcept;

  std::int64_t lead_ns() const noexcept { return lead_ns_; }

 private:
  std::int64_t lead_ns_ = 0;
  std::array<Vec3, client::kMaxJoints> axis_parent_{};  // hinge axes, model order
};

}  // namespace mocap::publish
