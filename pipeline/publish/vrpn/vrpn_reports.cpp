// Design: see vrpn_reports.h (payloads as vrpn_Tracker::encode_to / encode_vel_to).
#include "pipeline/publish/vrpn/vrpn_reports.h"

#include <cmath>

namespace mocap::publish::vrpn {

std::size_t encode_frame_reports(const FrameResult& f, std::size_t n_bodies, double dt, WireTime t,
                                 std::uint32_t& sequence, std::uint8_t* out, std::size_t cap,
                                 std::uint64_t& reports) noexcept {
  std::size_t bytes = 0;
  for (std::size_t b = 0; b < n_bodies && b < f.bodies.size(); ++b) {
    const ResultBody& body = f.bodies[b];
    if (body.found == 0) continue;
    const auto sender = static_cast<std::int32_t>(b);
    const auto& q = body.q_world_body;  // w, x, y, z -> VRPN's x, y, z, w
    const double pos[3] = {body.t_world_body_mm[0] / 1000.0, body.t_world_body_mm[1] / 1000.0,
                           body.t_world_body_mm[2] / 1000.0};
    const double quat[4] = {q[1], q[2], q[3], q[0]};
    std::uint8_t payload[kVelocityPayloadBytes];
    write_pos_quat(payload, 0, pos, quat);
    std::size_t n = write_message(out + bytes, cap - bytes, kTypePosQuat, sender, t, sequence,
                                  payload, kPosQuatPayloadBytes);
    if (n == 0) break;
    bytes += n;
    ++sequence;
    ++reports;
    if (body.velocity_valid == 0) continue;
    const double wx = static_cast<double>(body.w_world_rad_s[0]);
    const double wy = static_cast<double>(body.w_world_rad_s[1]);
    const double wz = static_cast<double>(body.w_world_rad_s[2]);
    const double rate = std::sqrt(wx * wx + wy * wy + wz * wz);  // rad/s
    const double angle = rate * dt;
    const double k = angle > 1e-12 ? std::sin(angle / 2) / rate : dt / 2;  // sin(a/2) / |w|
    const double dq[4] = {wx * k, wy * k, wz * k, std::cos(angle / 2)};
    const double vel[3] = {static_cast<double>(body.v_world_mm_s[0]) / 1000.0,
                           static_cast<double>(body.v_world_mm_s[1]) / 1000.0,
                           static_cast<double>(body.v_world_mm_s[2]) / 1000.0};
    write_velocity(payload, 0, vel, dq, dt);
    n = write_message(out + bytes, cap - bytes, kTypeVelocity, sender, t, sequence, payload,
                      kVelocityPayloadBytes);
    if (n == 0) break;
    bytes += n;
    ++sequence;
    ++reports;
  }
  return bytes;
}

}  // namespace mocap::publish::vrpn
