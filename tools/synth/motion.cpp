#include "tools/synth/motion.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace parallax::synth {
namespace {

using Eigen::Vector3d;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

SE3d Shake(const CameraRig& rig, double t, double amplitude_scale, double frequency_scale) {
  const double a = rig.shake_amplitude * amplitude_scale;
  const double f = frequency_scale;
  const Vector3d offset(std::sin(kTwoPi * 0.55 * f * t + 0.3),
                        0.7 * std::sin(kTwoPi * 0.4 * f * t + 1.1),
                        0.8 * std::sin(kTwoPi * 0.3 * f * t + 2.0));
  const Vector3d position = rig.start + a * offset;
  const double look_distance = (rig.look_at - rig.start).norm();
  const Vector3d wobble(std::sin(kTwoPi * 0.7 * f * t), std::sin(kTwoPi * 0.5 * f * t + 1.0), 0.0);
  const Vector3d target = rig.look_at + 0.04 * look_distance * wobble;
  return SE3d(LookAt(position, target), position);
}

SE3d Walk(const CameraRig& rig, double t) {
  const Vector3d forward = rig.walk_direction.normalized();
  const Vector3d side = Vector3d(0, 1, 0).cross(forward).normalized();
  const Vector3d position = rig.start + rig.walk_speed * t * forward +
                            0.03 * std::sin(kTwoPi * 0.9 * t) * side +
                            Vector3d(0, 0.02 * std::sin(kTwoPi * 1.8 * t), 0);
  const Vector3d target = position + 3.0 * forward + 0.1 * std::sin(kTwoPi * 0.3 * t) * side;
  return SE3d(LookAt(position, target), position);
}

// A racetrack centred on the start line: leg out at -r sideways, U-turn, leg back at +r,
// U-turn; the camera looks 3 m ahead along the direction of travel, with the walk's sway.
SE3d Patrol(const CameraRig& rig, double t) {
  const Vector3d f = rig.walk_direction.normalized();
  const Vector3d side = Vector3d(0, 1, 0).cross(f).normalized();
  const double L = rig.patrol_length;
  const double r = rig.patrol_radius;
  const double half_turn = std::numbers::pi * r;
  const double s = std::fmod(rig.walk_speed * t, 2.0 * L + 2.0 * half_turn);
  const Vector3d origin = rig.start - r * side;
  Vector3d position, heading;
  if (s < L) {
    position = origin + s * f;
    heading = f;
  } else if (s < L + half_turn) {
    const double a = (s - L) / r;
    position = origin + L * f + r * side + r * (-std::cos(a) * side + std::sin(a) * f);
    heading = std::sin(a) * side + std::cos(a) * f;
  } else if (s < 2.0 * L + half_turn) {
    position = origin + (2.0 * L + half_turn - s) * f + 2.0 * r * side;
    heading = -f;
  } else {
    const double a = (s - 2.0 * L - half_turn) / r;
    position = origin + r * side + r * (std::cos(a) * side - std::sin(a) * f);
    heading = -std::sin(a) * side - std::cos(a) * f;
  }
  const Vector3d across = Vector3d(0, 1, 0).cross(heading).normalized();
  position += 0.03 * std::sin(kTwoPi * 0.9 * t) * across +
              Vector3d(0, 0.02 * std::sin(kTwoPi * 1.8 * t), 0);
  const Vector3d target = position + 3.0 * heading + 0.1 * std::sin(kTwoPi * 0.3 * t) * across;
  return SE3d(LookAt(position, target), position);
}

SE3d Orbit(const CameraRig& rig, double t, double duration) {
  const double phi = duration > 0.0 ? kTwoPi * t / duration : 0.0;
  const Vector3d position(rig.orbit_centre.x() + rig.orbit_radius * std::sin(phi), rig.start.y(),
                          rig.orbit_centre.z() - rig.orbit_radius * std::cos(phi));
  return SE3d(LookAt(position, rig.orbit_centre), position);
}

SE3d Rotate(const CameraRig& rig, double t, double duration) {
  const double third = duration / 3.0;
  const Vector3d side =
      Vector3d(0, 1, 0).cross((rig.look_at - rig.start).normalized()).normalized();
  const double speed = 0.3;  // m/s sideways in the translating phases
  const double moved = speed * (std::min(t, third) + std::max(0.0, t - 2.0 * third));
  const Vector3d position = rig.start + moved * side;
  const SO3d base = LookAt(position, rig.look_at + moved * side);
  double yaw = 0.0;
  if (t > third && t < 2.0 * third) yaw = 0.6 * std::sin(std::numbers::pi * (t - third) / third);
  // Yaw about the camera's own y (down) axis: R_w_c * Exp(yaw e_y).
  return SE3d(base * SO3d::Exp(Vector3d(0, yaw, 0)), position);
}

}  // namespace

std::vector<std::string> MotionNames() {
  return {"shake", "walk", "orbit", "rotate", "fast", "patrol"};
}

Motion MotionFromString(const std::string& name) {
  if (name == "shake") return Motion::kShake;
  if (name == "walk") return Motion::kWalk;
  if (name == "orbit") return Motion::kOrbit;
  if (name == "rotate") return Motion::kRotate;
  if (name == "fast") return Motion::kFast;
  if (name == "patrol") return Motion::kPatrol;
  throw std::invalid_argument("unknown motion '" + name +
                              "' (expected shake, walk, orbit, rotate, fast or patrol)");
}

SO3d LookAt(const Vector3d& position, const Vector3d& target) {
  const Vector3d z = (target - position).normalized();
  Vector3d x = Vector3d(0, 1, 0).cross(z);
  if (x.norm() < 1e-6) x = Vector3d(1, 0, 0);  // looking straight up or down
  x.normalize();
  const Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R << x, y, z;
  return SO3d(R);
}

SE3d CameraPose(Motion motion, const CameraRig& rig, double t, double duration) {
  switch (motion) {
    case Motion::kShake:
      return Shake(rig, t, 1.0, 1.0);
    case Motion::kFast:
      return Shake(rig, t, 2.0, 2.5);
    case Motion::kWalk:
      return Walk(rig, t);
    case Motion::kOrbit:
      return Orbit(rig, t, duration);
    case Motion::kRotate:
      return Rotate(rig, t, duration);
    case Motion::kPatrol:
      return Patrol(rig, t);
  }
  return SE3d();
}

}  // namespace parallax::synth
