// The box model: loads cleanly, applies the box parameters, drives the base exactly, and its
// end stops stop, overshoot and settle.
#include <cmath>

#include <gtest/gtest.h>

#include "estimator/sample.hpp"
#include "tests/twin/mujoco_fixture.hpp"
#include "twin/flip_schedule.hpp"
#include "twin/motion.hpp"
#include "twin/world.hpp"

namespace driftless::twin {
namespace {

using testing::MujocoTest;

class WorldTest : public MujocoTest {};

TEST_F(WorldTest, InlineXmlLoadsAndBadXmlNamesTheProblem) {
  auto m = load_xml("<mujoco><worldbody><body><joint type='hinge'/><geom size='0.1'/></body></worldbody></mujoco>");
  EXPECT_EQ(m->nv, 1);
  try {
    load_mjcf_string("<mujoco><worldbody><body><jont/></body></worldbody></mujoco>");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("jont"), std::string::npos) << e.what();
  }
}

TEST_F(WorldTest, ShippedModelHasTheNamedParts) {
  World w(BoxParams{});
  const mjModel* m = w.model();
  for (const char* cam : {"cam_overview", "cam_side", "cam_track", "cam_closeup"}) {
    EXPECT_GE(mj_name2id(m, mjOBJ_CAMERA, cam), 0) << cam;
  }
  for (const char* s : {"gyro1", "accel1", "gyro2", "accel2"}) EXPECT_GE(mj_name2id(m, mjOBJ_SENSOR, s), 0) << s;
  for (const char* b : {"box", "platform1", "platform2", "pantilt_pan", "pantilt_tilt", "vehicle", "ship"}) {
    EXPECT_GE(mj_name2id(m, mjOBJ_BODY, b), 0) << b;
  }
  EXPECT_EQ(m->nu, 2);
  EXPECT_NEAR(m->opt.timestep, 0.001, 0);
}

TEST_F(WorldTest, BoxParamsPatchAxesStopsAndMotor) {
  BoxParams b;
  b.hinge2_axis = Eigen::Vector3d(0, 2, 0);  // normalised by the model
  b.stop1_error_deg = Eigen::Vector2d(0.3, -0.2);
  b.motor.kp_nm_per_rad = 0.1;
  World w(b);
  const mjModel* m = w.model();
  const int j1 = mj_name2id(m, mjOBJ_JOINT, "hinge1"), j2 = mj_name2id(m, mjOBJ_JOINT, "hinge2");
  EXPECT_NEAR(m->jnt_axis[3 * j2 + 1], 1.0, 1e-12);
  EXPECT_NEAR(m->jnt_range[2 * j1 + 0], (-90 + 0.3) * kRadPerDeg, 1e-12);
  EXPECT_NEAR(m->jnt_range[2 * j1 + 1], (90 - 0.2) * kRadPerDeg, 1e-12);
  EXPECT_NEAR(m->actuator_gainprm[mjNGAIN * 0], 0.1, 1e-15);
  EXPECT_NEAR(b.stop_rad(1, +1), (90 - 0.2) * kRadPerDeg, 1e-15);
}

TEST_F(WorldTest, BadBoxParamsAreRejectedWithTheFieldName) {
  BoxParams b;
  b.hinge2_axis = Eigen::Vector3d(0, 0, 3);  // parallel to hinge 1
  EXPECT_THROW(b.validate(), std::invalid_argument);
  b = BoxParams{};
  b.stop_dampratio = 0.2;
  try {
    b.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("stop_dampratio"), std::string::npos);
  }
}

// GIVEN a static box, WHEN the motor drives platform 1 from its - stop onto its + stop,
// THEN the platform overshoots into the compliant stop, settles on it, and never passes it by more
// than a small penetration
TEST_F(WorldTest, EndStopOvershootAndSettling) {
  BoxParams b;
  b.stop1_error_deg = Eigen::Vector2d(0, 0.2);
  World w(b);
  mjModel* m = w.model();
  const double stop = b.stop_rad(1, +1);
  w.set_platform(1, b.stop_rad(1, -1));
  w.set_platform(2, b.stop_rad(2, +1));
  const double overtravel = b.motor.overtravel_deg * kRadPerDeg;
  TrapezoidProfile ref(0.0, -(b.end_stop_deg * kRadPerDeg + overtravel), b.end_stop_deg * kRadPerDeg + overtravel,
                       b.motor.max_speed_dps * kRadPerDeg, b.motor.max_accel_dps2 * kRadPerDeg);
  double peak = -10, t_hit = -1, max_rate = 0;
  double t = 0;
  const MotionState at_rest;
  for (int n = 0; n < 4000; ++n, t += m->opt.timestep) {
    w.step_driven(t, at_rest, Eigen::Vector2d(ref.angle_rad(t), 93 * kRadPerDeg));
    const double q = w.platform_angle_rad(1);
    peak = std::max(peak, q);
    max_rate = std::max(max_rate, std::abs(w.platform_rate_radps(1)));
    if (t_hit < 0 && q >= stop) t_hit = t;
  }
  // the motor's speed limit holds (servo lag adds a little)
  EXPECT_LT(max_rate, 1.1 * b.motor.max_speed_dps * kRadPerDeg);
  EXPECT_GT(max_rate, 0.9 * b.motor.max_speed_dps * kRadPerDeg);
  ASSERT_GT(t_hit, 0) << "platform never reached its stop";
  const double overshoot_deg = (peak - stop) * kDegPerRad;
  EXPECT_GT(overshoot_deg, 0.005) << "no overshoot into the stop";
  EXPECT_LT(overshoot_deg, 0.5);
  // settled: at rest on the stop, pressed in by the motor torque only slightly
  EXPECT_LT(std::abs(w.platform_rate_radps(1)), 1e-9);
  EXPECT_NEAR(w.platform_angle_rad(1), stop, 0.02 * kRadPerDeg);
  EXPECT_GE(w.platform_angle_rad(1), stop);
}

// GIVEN a prescribed base acceleration, WHEN the drive applies its force, THEN MuJoCo's qacc of
// the box equals it (the drive imposes the trajectory's dynamics)
TEST_F(WorldTest, DriveImposesTheBaseAcceleration) {
  World w(BoxParams{});
  mjModel* m = w.model();
  mjData* d = w.data();
  const Eigen::Vector3d a(0.7, -1.3, 2.1), dw(0.4, -0.2, 0.9);
  w.set_base(Eigen::Vector3d(1, 2, 3), Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
             Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d(0.1, 0.2, -0.3));
  mj_step1(m, d);
  w.drive_base(a, dw);
  mj_forward(m, d);  // recompute qacc with the drive force in place
  const int dof = m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "drive_x")];
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(d->qacc[dof + k], a[k], 1e-6);
    EXPECT_NEAR(d->qacc[dof + 3 + k], dw[k], 1e-6);
  }
}

}  // namespace
}  // namespace driftless::twin

namespace driftless::twin {
namespace {

// GIVEN the shipped model and its physics-only scope, WHEN both are driven through the same
// moves, THEN the physics scope has no carriers, cameras or decorations and its dynamics are the
// same to the last bit (the decorations are massless, contact-free or mocap)
TEST_F(WorldTest, PhysicsScopeDropsDecorationsAndKeepsTheDynamics) {
  BoxParams b;
  b.stop1_error_deg = Eigen::Vector2d(0.1, -0.2);
  World full(b), phys(b, 0.001, ModelScope::physics);
  EXPECT_LT(phys.model()->ngeom, full.model()->ngeom / 3);
  EXPECT_EQ(phys.model()->ncam, 0);
  EXPECT_EQ(phys.model()->nmocap, 0);
  EXPECT_EQ(phys.model()->nv, full.model()->nv);
  EXPECT_EQ(phys.model()->nsensor, full.model()->nsensor);
  EXPECT_TRUE(full.model()->opt.disableflags & mjDSBL_CONTACT) << "no geom collides: contacts off";
  MotionState base;
  base.q_enu_from_body = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  base.w_body_radps = Eigen::Vector3d(0.2, -0.1, 0.3);
  base.dw_body_radps2 = Eigen::Vector3d(1.0, 2.0, -3.0);
  base.a_enu_mps2 = Eigen::Vector3d(0.5, -0.2, 1.0);
  for (World* w : {&full, &phys}) {
    w->set_platform(1, b.stop_rad(1, +1));
    w->set_platform(2, b.stop_rad(2, -1));
  }
  for (int n = 0; n < 500; ++n) {
    const double t = n * 0.001;
    const Eigen::Vector2d ref(std::sin(5 * t), -1.6);
    const HingeState a = full.step_driven(t, base, ref), p = phys.step_driven(t, base, ref, n % 10 == 0);
    for (int i = 0; i < 2; ++i) {
      ASSERT_EQ(a.angle_rad[i], p.angle_rad[i]) << "step " << n;
      ASSERT_EQ(a.rate_radps[i], p.rate_radps[i]) << "step " << n;
    }
    if (n % 10 == 0) {
      for (int i = 1; i <= 2; ++i) {
        ASSERT_EQ(full.mj_gyro(i), phys.mj_gyro(i)) << "step " << n;
        ASSERT_EQ(full.mj_accel(i), phys.mj_accel(i)) << "step " << n;
      }
    }
  }
  EXPECT_THROW(phys.pose_carrier(Carrier::vehicle, base.p_enu_m, base.q_enu_from_body), std::logic_error);
}

}  // namespace
}  // namespace driftless::twin

namespace driftless::twin {
namespace {

// a tilted box on a base that moves, turns and accelerates, with hinges off the default axes (so
// the platforms' centres of mass sit off their axes and gravity loads the hinges)
struct MovingBase {
  BoxParams box;
  MotionState base;
  MovingBase() {
    box.hinge1_axis = Eigen::Vector3d(0.3, 0.2, 1.0);
    box.hinge2_axis = Eigen::Vector3d(1.0, -0.4, 0.1);
    base.p_enu_m = Eigen::Vector3d(1, -2, 0.5);
    base.q_enu_from_body = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 3).normalized()));
    base.v_enu_mps = Eigen::Vector3d(3, 1, 0);
    base.a_enu_mps2 = Eigen::Vector3d(0.8, -1.5, 2.0);
    base.w_body_radps = Eigen::Vector3d(0.4, -0.3, 0.9);
    base.dw_body_radps2 = Eigen::Vector3d(2.0, -3.0, 1.5);
  }
};

// GIVEN a moving base and platforms mid-flip, WHEN MuJoCo steps, THEN the closed-form site
// kinematics give MuJoCo's gyro and accelerometer readings (the rest path's truth)
TEST_F(WorldTest, SiteKinematicsMatchMujocoSensors) {
  MovingBase mb;
  World w(mb.box, 0.001, ModelScope::physics);
  w.set_platform(1, 0.4, 1.5);
  w.set_platform(2, -0.9, -2.0);
  double worst_w = 0, worst_f = 0;
  for (int n = 0; n < 50; ++n) {
    const HingeState h = w.step_driven(n * 0.001, mb.base, Eigen::Vector2d(0.2, -0.5));
    for (int i = 1; i <= 2; ++i) {
      const SiteMotion sm = w.site_motion(i, mb.base, h.angle_rad[i - 1], h.rate_radps[i - 1], w.platform_accel_radps2(i));
      worst_w = std::max(worst_w, (sm.w_radps - w.mj_gyro(i)).norm());
      worst_f = std::max(worst_f, (sm.f_mps2 - w.mj_accel(i)).norm());
    }
  }
  // the drive imposes the base acceleration up to the platforms' reaction on the 1e6 armature
  EXPECT_LT(worst_w, 1e-12);
  EXPECT_LT(worst_f, 1e-8);
}

// GIVEN a platform held still off its stops on a moving base, WHEN MuJoCo's inverse dynamics
// give the hinge torque that keeps it so, THEN the closed-form rest torque equals it
TEST_F(WorldTest, RestHingeTorqueIsTheInverseDynamics) {
  MovingBase mb;
  World w(mb.box, 0.001, ModelScope::physics);
  mjModel* m = w.model();
  mjData* d = w.data();
  const double angle[2] = {0.3, -0.6};
  w.set_base(mb.base.p_enu_m, mb.base.q_enu_from_body, mb.base.v_enu_mps, mb.base.w_body_radps);
  for (int i = 1; i <= 2; ++i) w.set_platform(i, angle[i - 1], 0.0);
  mj_forward(m, d);
  const int drive = m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "drive_x")];
  for (int k = 0; k < m->nv; ++k) d->qacc[k] = 0.0;
  for (int k = 0; k < 3; ++k) {
    d->qacc[drive + k] = mb.base.a_enu_mps2[k];
    d->qacc[drive + 3 + k] = mb.base.dw_body_radps2[k];
  }
  mj_inverse(m, d);
  for (int i = 1; i <= 2; ++i) {
    const int dof = m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, i == 1 ? "hinge1" : "hinge2")];
    const double tau = w.rest_hinge_torque_nm(i, mb.base, angle[i - 1]);
    EXPECT_GT(std::abs(tau), 1e-6) << "platform " << i << ": a test without load proves nothing";
    EXPECT_NEAR(tau, d->qfrc_inverse[dof], 1e-12) << "platform " << i;
  }
  // the servo at rest: stiffness times the reference's lead, clipped to the stall torque
  EXPECT_NEAR(w.motor_rest_torque_nm(0.01, 0.0), mb.box.motor.kp_nm_per_rad * 0.01, 1e-15);
  EXPECT_EQ(w.motor_rest_torque_nm(-3.0, 0.0), -mb.box.motor.stall_torque_nm);
}

}  // namespace
}  // namespace driftless::twin
