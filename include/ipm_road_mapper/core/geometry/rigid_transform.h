// Rigid transforms and SE(3) interpolation.
//
// Convention (used everywhere in the package): T_a_b is an Eigen::Isometry3d that maps
// points expressed in frame b into frame a, p_a = T_a_b * p_b. So T_map_base is the
// vehicle pose in the map and T_base_cam the camera extrinsic (the paper's R_b^c, t_b^c).
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <vector>

namespace ipm_road_mapper {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// SO(3) exponential map: rotation vector (axis * angle, rad) -> rotation matrix.
Eigen::Matrix3d ExpSo3(const Eigen::Vector3d& omega);

// SO(3) logarithm: rotation matrix -> rotation vector with angle in [0, pi].
Eigen::Vector3d LogSo3(const Eigen::Matrix3d& R);

// SE(3) exponential map of the twist xi = [rho; omega] (translation part first).
Eigen::Isometry3d ExpSe3(const Vector6d& xi);

// SE(3) logarithm, the inverse of ExpSe3: returns [rho; omega].
Vector6d LogSe3(const Eigen::Isometry3d& T);

// Geodesic interpolation on SE(3): T_a * Exp(alpha * Log(T_a^-1 * T_b)), alpha in [0, 1].
Eigen::Isometry3d InterpolateSe3(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b,
                                 double alpha);

// Rotation angle (rad) of the relative rotation between two transforms.
double RotationAngleBetween(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b);

// Builds a rotation from roll, pitch, yaw (rad), applied as R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Matrix3d RotationFromRpy(double roll, double pitch, double yaw);

// Inverse of RotationFromRpy: returns (roll, pitch, yaw) in rad.
Eigen::Vector3d RpyFromRotation(const Eigen::Matrix3d& R);

// True when every coefficient of the transform is finite and its rotation is orthonormal.
bool IsValidTransform(const Eigen::Isometry3d& T);

// A pose of base_link in the map at a time stamp (seconds).
struct StampedPose {
  double stamp = 0.0;
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
};

// Why a pose could not be interpolated at a requested stamp.
enum class PoseLookupStatus {
  kOk,
  kEmpty,         // no pose at all
  kBeforeFirst,   // stamp earlier than the first pose by more than the tolerance
  kAfterLast,     // stamp later than the last pose by more than the tolerance
  kGapTooLarge,   // bracketing poses farther apart than the allowed gap
  kInvalidStamp,  // the requested stamp is NaN
};

// Human-readable name of a lookup status (for logs and skip counters).
const char* ToString(PoseLookupStatus status);

// A time-ordered buffer of odometry poses that interpolates on SE(3) at a query stamp.
// A stamp outside the buffer is accepted only within `extrapolation_tolerance_s` (the
// nearest pose is returned, never extrapolated); two bracketing poses farther apart than
// `max_gap_s` give kGapTooLarge. Not thread-safe: the caller owns the locking.
class PoseBuffer {
 public:
  PoseBuffer(double extrapolation_tolerance_s, double max_gap_s, std::size_t capacity);

  // Adds a pose. Returns false (and keeps the buffer) for a non-finite pose or a stamp not
  // after the newest one; a caller that sees time jump backwards should Clear() first.
  bool Add(const StampedPose& pose);

  // Interpolated pose at `stamp`, or the reason it cannot be given.
  PoseLookupStatus Lookup(double stamp, Eigen::Isometry3d* T_map_base) const;

  void Clear() { poses_.clear(); }
  std::size_t size() const { return poses_.size(); }
  bool empty() const { return poses_.empty(); }
  const StampedPose& newest() const { return poses_.back(); }

 private:
  double extrapolation_tolerance_s_;
  double max_gap_s_;
  std::size_t capacity_;
  std::vector<StampedPose> poses_;  // sorted by stamp; trimmed from the front at capacity
};

}  // namespace ipm_road_mapper
