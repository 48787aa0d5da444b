// A GoogleTest fixture for MuJoCo code (after MuJoCo's test/fixture.h MujocoTest): any MuJoCo
// warning or error during a test fails it, and models load from inline XML.
#pragma once

#include <string>

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include "twin/world.hpp"

namespace driftless::twin::testing {

class MujocoTest : public ::testing::Test {
 protected:
  MujocoTest() {
    mju_user_warning = [](const char* msg) { FAIL() << "MuJoCo warning: " << msg; };
  }
  ~MujocoTest() override { mju_user_warning = nullptr; }

  /// Loads MJCF text (fails the test with MuJoCo's message if it does not load).
  static ModelPtr load_xml(const std::string& xml) { return load_mjcf_string(xml, "inline.xml"); }
};

}  // namespace driftless::twin::testing
