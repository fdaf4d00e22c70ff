// Tests of the SE(3) tools: exponential / logarithm, interpolation, roll-pitch-yaw and the
// odometry pose buffer. The exponential is checked against an independent reference (the
// 4x4 matrix exponential of the twist), so a wrong left Jacobian or a swapped [rho; omega]
// order cannot pass by being self-consistent.
#include <gtest/gtest.h>

#include <cmath>
#include <iterator>
#include <limits>
#include <set>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>

#include "ipm_road_mapper/core/geometry/rigid_transform.h"

namespace ipm_road_mapper {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Vector6d Twist(double rx, double ry, double rz, double wx, double wy, double wz) {
  Vector6d xi;
  xi << rx, ry, rz, wx, wy, wz;
  return xi;
}

// exp([hat(omega) rho; 0 0]) computed by Eigen's general matrix exponential.
Eigen::Isometry3d ReferenceExpSe3(const Vector6d& xi) {
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  const Eigen::Vector3d w = xi.tail<3>();
  A.topLeftCorner<3, 3>() << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  A.topRightCorner<3, 1>() = xi.head<3>();
  Eigen::Isometry3d T;
  T.matrix() = A.exp();
  return T;
}

// Max abs difference of two transforms (rotation and translation coefficients).
double TransformDiff(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

Eigen::Isometry3d MakeTransform(const Vector6d& xi) { return ReferenceExpSe3(xi); }

TEST(ExpSe3, MatchesMatrixExponentialOverAllAngleScales) {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  const Eigen::Vector3d rho(1.7, -2.3, 0.9);
  for (double angle :
       {0.0, 1e-12, 1e-9, 1e-8, 3e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 0.1, 1.0, 2.5, M_PI - 1e-6}) {
    Vector6d xi;
    xi << rho, angle * axis;
    const Eigen::Isometry3d T = ExpSe3(xi);
    const Eigen::Isometry3d T_ref = ReferenceExpSe3(xi);
    EXPECT_LT(TransformDiff(T, T_ref), 1e-12) << "angle " << angle << "\nT:\n"
                                              << T.matrix() << "\nref:\n"
                                              << T_ref.matrix();
  }
}

TEST(ExpSe3, PureTranslationAndPureRotation) {
  const Eigen::Isometry3d T_trans = ExpSe3(Twist(1.0, 2.0, 3.0, 0.0, 0.0, 0.0));
  EXPECT_TRUE(T_trans.linear().isIdentity(1e-15));
  EXPECT_TRUE(T_trans.translation().isApprox(Eigen::Vector3d(1.0, 2.0, 3.0), 1e-15));

  // A quarter turn about z maps x to y (right-handed, translation part first in xi).
  const Eigen::Isometry3d T_rot = ExpSe3(Twist(0.0, 0.0, 0.0, 0.0, 0.0, M_PI / 2));
  EXPECT_LT((T_rot.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-15);
  EXPECT_LT(T_rot.translation().norm(), 1e-15);
}

TEST(LogSe3, RoundTripsExpSe3IncludingSmallAndNearPiAngles) {
  const Eigen::Vector3d axis = Eigen::Vector3d(-0.2, 0.9, 0.4).normalized();
  const Eigen::Vector3d rho(-0.4, 3.1, 1.2);
  for (double angle :
       {0.0, 1e-12, 1e-9, 1e-8, 1e-7, 1e-5, 0.3, 1.5, 3.0, M_PI - 1e-4, M_PI - 1e-6}) {
    Vector6d xi;
    xi << rho, angle * axis;
    const Vector6d xi_back = LogSe3(ExpSe3(xi));
    EXPECT_LT((xi_back - xi).cwiseAbs().maxCoeff(), 1e-9)
        << "angle " << angle << "\nxi " << xi.transpose() << "\nback " << xi_back.transpose();
    // Exp(Log(T)) = T holds even where Log is ill-conditioned.
    const Eigen::Isometry3d T = ReferenceExpSe3(xi);
    EXPECT_LT(TransformDiff(ExpSe3(LogSe3(T)), T), 1e-10) << "angle " << angle;
  }
}

TEST(LogSe3, ExactlyPiRotationStillRoundTrips) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d(1.0, 1.0, 0.0).normalized()).matrix();
  T.translation() = Eigen::Vector3d(0.5, -1.0, 2.0);
  const Vector6d xi = LogSe3(T);
  EXPECT_NEAR(xi.tail<3>().norm(), M_PI, 1e-9);
  EXPECT_LT(TransformDiff(ExpSe3(xi), T), 1e-9);
}

TEST(LogSo3, AngleInZeroToPi) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, 2.0, -1.0).normalized();
  // A rotation by 1.5 pi is the rotation by 0.5 pi about the opposite axis.
  const Eigen::Vector3d omega = LogSo3(ExpSo3(1.5 * M_PI * axis));
  EXPECT_NEAR(omega.norm(), 0.5 * M_PI, 1e-12);
  EXPECT_LT((omega.normalized() + axis).norm(), 1e-12);
}

TEST(InterpolateSe3, EndpointsAreTheInputs) {
  const Eigen::Isometry3d T_a = MakeTransform(Twist(1.0, 2.0, 0.5, 0.1, -0.2, 0.3));
  const Eigen::Isometry3d T_b = MakeTransform(Twist(4.0, -1.0, 0.2, -0.3, 0.4, 1.2));
  EXPECT_LT(TransformDiff(InterpolateSe3(T_a, T_b, 0.0), T_a), 1e-12);
  EXPECT_LT(TransformDiff(InterpolateSe3(T_a, T_b, 1.0), T_b), 1e-12);
}

TEST(InterpolateSe3, MidpointOfPureRotationIsHalfTheAngle) {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, -0.3, 0.9).normalized();
  const double angle = 1.2;
  Eigen::Isometry3d T_b = Eigen::Isometry3d::Identity();
  T_b.linear() = Eigen::AngleAxisd(angle, axis).matrix();
  const Eigen::Isometry3d T_mid = InterpolateSe3(Eigen::Isometry3d::Identity(), T_b, 0.5);
  const Eigen::AngleAxisd aa(T_mid.linear());
  EXPECT_NEAR(aa.angle(), angle / 2, 1e-12);
  EXPECT_LT((aa.axis() - axis).norm(), 1e-12);
  EXPECT_LT(T_mid.translation().norm(), 1e-12);
}

TEST(InterpolateSe3, ConstantTwistMotionIsInterpolatedExactly) {
  // A screw motion (rotation about z while translating along x and z): sampling the
  // interpolation at alpha gives T_a * Exp(alpha * xi), which is not the linear
  // interpolation of the translations.
  const Eigen::Isometry3d T_a = MakeTransform(Twist(10.0, -5.0, 1.0, 0.05, -0.02, 0.7));
  const Vector6d xi = Twist(3.0, 0.0, 0.4, 0.0, 0.0, 1.1);
  const Eigen::Isometry3d T_b = T_a * ReferenceExpSe3(xi);
  for (double alpha : {0.1, 0.25, 0.5, 0.8}) {
    const Eigen::Isometry3d expected = T_a * ReferenceExpSe3(alpha * xi);
    const Eigen::Isometry3d actual = InterpolateSe3(T_a, T_b, alpha);
    EXPECT_LT(TransformDiff(actual, expected), 1e-11) << "alpha " << alpha;
    const Eigen::Vector3d linear = (1 - alpha) * T_a.translation() + alpha * T_b.translation();
    EXPECT_GT((actual.translation() - linear).norm(), 1e-3) << "alpha " << alpha;
  }
}

TEST(RotationFromRpy, MatchesZyxCompositionAndRep103Signs) {
  const double roll = 0.3, pitch = -0.2, yaw = 1.1;
  Eigen::Matrix3d Rx, Ry, Rz;
  Rx << 1, 0, 0, 0, std::cos(roll), -std::sin(roll), 0, std::sin(roll), std::cos(roll);
  Ry << std::cos(pitch), 0, std::sin(pitch), 0, 1, 0, -std::sin(pitch), 0, std::cos(pitch);
  Rz << std::cos(yaw), -std::sin(yaw), 0, std::sin(yaw), std::cos(yaw), 0, 0, 0, 1;
  EXPECT_LT((RotationFromRpy(roll, pitch, yaw) - Rz * Ry * Rx).norm(), 1e-15);

  // Positive yaw turns x toward y (left); positive pitch turns x toward -z (nose down);
  // positive roll turns y toward z.
  const Eigen::Vector3d x_yawed = RotationFromRpy(0, 0, 0.1) * Eigen::Vector3d::UnitX();
  EXPECT_GT(x_yawed.y(), 0.0);
  const Eigen::Vector3d x_pitched = RotationFromRpy(0, 0.1, 0) * Eigen::Vector3d::UnitX();
  EXPECT_LT(x_pitched.z(), 0.0);
  const Eigen::Vector3d y_rolled = RotationFromRpy(0.1, 0, 0) * Eigen::Vector3d::UnitY();
  EXPECT_GT(y_rolled.z(), 0.0);
}

TEST(RpyFromRotation, InvertsRotationFromRpy) {
  for (double roll : {-3.0, -1.0, 0.0, 0.4, 2.9}) {
    for (double pitch : {-1.5, -0.7, 0.0, 0.2, 1.5}) {
      for (double yaw : {-3.1, -0.5, 0.0, 1.3, 3.1}) {
        const Eigen::Vector3d rpy = RpyFromRotation(RotationFromRpy(roll, pitch, yaw));
        EXPECT_NEAR(rpy.x(), roll, 1e-9);
        EXPECT_NEAR(rpy.y(), pitch, 1e-9);
        EXPECT_NEAR(rpy.z(), yaw, 1e-9);
      }
    }
  }
}

TEST(RotationAngleBetween, IsTheRelativeRotationAngle) {
  const Eigen::Isometry3d T_a = MakeTransform(Twist(1.0, 2.0, 3.0, 0.4, -0.1, 0.7));
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  delta.linear() = Eigen::AngleAxisd(0.37, Eigen::Vector3d(1, -1, 2).normalized()).matrix();
  delta.translation() = Eigen::Vector3d(5.0, 0.0, -1.0);  // translation does not count
  const Eigen::Isometry3d T_b = T_a * delta;
  EXPECT_NEAR(RotationAngleBetween(T_a, T_b), 0.37, 1e-12);
  EXPECT_NEAR(RotationAngleBetween(T_b, T_a), 0.37, 1e-12);
  EXPECT_NEAR(RotationAngleBetween(T_a, T_a), 0.0, 1e-12);
}

TEST(IsValidTransform, AcceptsRigidRejectsNaNInfAndNonOrthonormal) {
  EXPECT_TRUE(IsValidTransform(Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(IsValidTransform(MakeTransform(Twist(1, 2, 3, 0.5, -0.5, 2.0))));

  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().y() = kNaN;
  EXPECT_FALSE(IsValidTransform(T));

  T = Eigen::Isometry3d::Identity();
  T.linear()(1, 2) = kNaN;
  EXPECT_FALSE(IsValidTransform(T));

  T = Eigen::Isometry3d::Identity();
  T.translation().x() = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(IsValidTransform(T));

  T = Eigen::Isometry3d::Identity();
  T.linear() *= 1.01;  // scaled
  EXPECT_FALSE(IsValidTransform(T));

  T = Eigen::Isometry3d::Identity();
  T.linear()(0, 1) = 0.05;  // sheared
  EXPECT_FALSE(IsValidTransform(T));

  T = Eigen::Isometry3d::Identity();
  T.linear()(2, 2) = -1.0;  // a reflection is orthogonal but not a rotation
  EXPECT_FALSE(IsValidTransform(T));
}

// ---------------------------------------------------------------------------------------
// PoseBuffer
// ---------------------------------------------------------------------------------------

// Poses of a vehicle moving with constant twist xi per 0.1 s from T0, at stamps 0, 0.1, ...
class PoseBufferTest : public ::testing::Test {
 protected:
  const Eigen::Isometry3d T0_ = MakeTransform(Twist(100.0, 50.0, 2.0, 0.0, 0.01, 0.5));
  const Vector6d xi_ = Twist(1.5, 0.05, 0.0, 0.001, 0.0, 0.08);

  Eigen::Isometry3d TruePose(double stamp) const {
    return T0_ * ReferenceExpSe3((stamp / 0.1) * xi_);
  }
  StampedPose PoseAt(double stamp) const { return {stamp, TruePose(stamp)}; }
};

TEST_F(PoseBufferTest, EmptyBufferReportsEmpty) {
  PoseBuffer buffer(0.05, 0.2, 10);
  Eigen::Isometry3d T;
  EXPECT_EQ(buffer.Lookup(1.0, &T), PoseLookupStatus::kEmpty);
  EXPECT_TRUE(buffer.empty());
}

TEST_F(PoseBufferTest, InterpolatesBetweenStamps) {
  PoseBuffer buffer(0.05, 0.2, 10);
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(buffer.Add(PoseAt(0.1 * i)));
  for (double stamp : {0.0, 0.013, 0.05, 0.1, 0.137, 0.25, 0.3}) {
    Eigen::Isometry3d T;
    ASSERT_EQ(buffer.Lookup(stamp, &T), PoseLookupStatus::kOk) << stamp;
    EXPECT_LT(TransformDiff(T, TruePose(stamp)), 1e-9) << "stamp " << stamp;
  }
}

TEST_F(PoseBufferTest, ToleranceAtTheEndsReturnsNearestPoseNeverExtrapolates) {
  PoseBuffer buffer(0.05, 0.2, 10);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(buffer.Add(PoseAt(1.0 + 0.1 * i)));
  Eigen::Isometry3d T;
  ASSERT_EQ(buffer.Lookup(0.96, &T), PoseLookupStatus::kOk);
  EXPECT_LT(TransformDiff(T, TruePose(1.0)), 1e-12);
  EXPECT_EQ(buffer.Lookup(0.94, &T), PoseLookupStatus::kBeforeFirst);
  ASSERT_EQ(buffer.Lookup(1.24, &T), PoseLookupStatus::kOk);
  EXPECT_LT(TransformDiff(T, TruePose(1.2)), 1e-12);
  EXPECT_EQ(buffer.Lookup(1.26, &T), PoseLookupStatus::kAfterLast);
}

TEST_F(PoseBufferTest, GapTooLargeBetweenBracketingPoses) {
  PoseBuffer buffer(0.05, 0.15, 10);
  ASSERT_TRUE(buffer.Add(PoseAt(0.0)));
  ASSERT_TRUE(buffer.Add(PoseAt(0.1)));
  ASSERT_TRUE(buffer.Add(PoseAt(0.4)));  // 0.3 s gap
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  EXPECT_EQ(buffer.Lookup(0.05, &T), PoseLookupStatus::kOk);
  EXPECT_EQ(buffer.Lookup(0.2, &T), PoseLookupStatus::kGapTooLarge);
  EXPECT_EQ(buffer.Lookup(0.39, &T), PoseLookupStatus::kGapTooLarge);
}

TEST_F(PoseBufferTest, RejectsNonIncreasingStampsAndInvalidPoses) {
  PoseBuffer buffer(0.05, 0.2, 10);
  ASSERT_TRUE(buffer.Add(PoseAt(1.0)));
  EXPECT_FALSE(buffer.Add(PoseAt(1.0)));  // same stamp
  EXPECT_FALSE(buffer.Add(PoseAt(0.9)));  // earlier stamp
  StampedPose nan_pose = PoseAt(1.1);
  nan_pose.T_map_base.translation().x() = kNaN;
  EXPECT_FALSE(buffer.Add(nan_pose));
  StampedPose nan_rotation = PoseAt(1.1);
  nan_rotation.T_map_base.linear()(0, 0) = kNaN;
  EXPECT_FALSE(buffer.Add(nan_rotation));
  StampedPose scaled = PoseAt(1.1);
  scaled.T_map_base.linear() *= 2.0;
  EXPECT_FALSE(buffer.Add(scaled));
  EXPECT_FALSE(buffer.Add(PoseAt(kNaN)));
  EXPECT_EQ(buffer.size(), 1u);
  EXPECT_DOUBLE_EQ(buffer.newest().stamp, 1.0);
  EXPECT_TRUE(buffer.Add(PoseAt(1.1)));
  EXPECT_EQ(buffer.size(), 2u);
}

TEST_F(PoseBufferTest, NonFiniteLookupStampIsRejected) {
  PoseBuffer buffer(0.05, 0.2, 10);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(buffer.Add(PoseAt(0.1 * i)));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  EXPECT_EQ(buffer.Lookup(kNaN, &T), PoseLookupStatus::kInvalidStamp);
  EXPECT_TRUE(T.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_EQ(buffer.Lookup(std::numeric_limits<double>::infinity(), &T),
            PoseLookupStatus::kAfterLast);
  EXPECT_EQ(buffer.Lookup(-std::numeric_limits<double>::infinity(), &T),
            PoseLookupStatus::kBeforeFirst);
}

TEST_F(PoseBufferTest, CapacityTrimsOldestPoses) {
  PoseBuffer buffer(0.01, 0.2, 3);
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(buffer.Add(PoseAt(0.1 * i)));
  EXPECT_EQ(buffer.size(), 3u);
  EXPECT_DOUBLE_EQ(buffer.newest().stamp, 0.4);
  Eigen::Isometry3d T;
  EXPECT_EQ(buffer.Lookup(0.1, &T), PoseLookupStatus::kBeforeFirst);  // trimmed
  ASSERT_EQ(buffer.Lookup(0.25, &T), PoseLookupStatus::kOk);
  EXPECT_LT(TransformDiff(T, TruePose(0.25)), 1e-9);

  // A capacity below 2 could never interpolate; it is raised to 2.
  PoseBuffer tiny(0.01, 0.2, 0);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(tiny.Add(PoseAt(0.1 * i)));
  EXPECT_EQ(tiny.size(), 2u);
  ASSERT_EQ(tiny.Lookup(0.15, &T), PoseLookupStatus::kOk);
}

TEST_F(PoseBufferTest, ClearAllowsTimeToJumpBack) {
  PoseBuffer buffer(0.01, 0.2, 10);
  ASSERT_TRUE(buffer.Add(PoseAt(5.0)));
  EXPECT_FALSE(buffer.Add(PoseAt(1.0)));
  buffer.Clear();
  EXPECT_TRUE(buffer.empty());
  EXPECT_TRUE(buffer.Add(PoseAt(1.0)));
}

TEST(PoseLookupStatus, EveryStatusHasADistinctName) {
  const PoseLookupStatus all[] = {PoseLookupStatus::kOk,          PoseLookupStatus::kEmpty,
                                  PoseLookupStatus::kBeforeFirst, PoseLookupStatus::kAfterLast,
                                  PoseLookupStatus::kGapTooLarge, PoseLookupStatus::kInvalidStamp};
  std::set<std::string> names;
  for (PoseLookupStatus s : all) {
    const std::string name = ToString(s);
    EXPECT_NE(name, "unknown");
    names.insert(name);
  }
  EXPECT_EQ(names.size(), std::size(all));
}

}  // namespace
}  // namespace ipm_road_mapper
