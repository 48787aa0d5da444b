// Small YAML helpers for the calibration files: typed reads that name file, line and key.
#pragma once

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include "estimator/input_error.hpp"
#include "estimator/numbers.hpp"

namespace driftless::calib::yio {

// the 1-based line of a node (0 when yaml-cpp knows none)
inline std::size_t line_of(const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  return m.line < 0 ? 0 : static_cast<std::size_t>(m.line) + 1;
}

[[noreturn]] inline void fail(const std::string& file, const YAML::Node& n, const std::string& key,
                              const std::string& msg) {
  throw InputError(file, line_of(n), key, msg);
}

inline double as_double(const YAML::Node& n, const std::string& file, const std::string& key) {
  double v = 0.0;
  if (!n || !n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
    fail(file, n, key, "expected a number");
  return v;
}

inline std::string as_string(const YAML::Node& n, const std::string& file, const std::string& key) {
  if (!n || !n.IsScalar()) fail(file, n, key, "expected a text value");
  return n.Scalar();
}

inline Eigen::Vector3d as_vec3(const YAML::Node& n, const std::string& file,
                               const std::string& key) {
  if (!n || !n.IsSequence() || n.size() != 3) fail(file, n, key, "expected [x, y, z]");
  return {as_double(n[0], file, key), as_double(n[1], file, key), as_double(n[2], file, key)};
}

// a 3x3 matrix written as three rows
inline Eigen::Matrix3d as_mat3(const YAML::Node& n, const std::string& file,
                               const std::string& key) {
  if (!n || !n.IsSequence() || n.size() != 3)
    fail(file, n, key, "expected a 3x3 matrix as three rows [[a, b, c], [d, e, f], [g, h, i]]");
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) m.row(r) = as_vec3(n[r], file, key).transpose();
  return m;
}

// numbers are written in their shortest exact form: a file read back gives the same doubles
inline std::string num(double v) { return exact_number(v); }

inline void emit_vec3(YAML::Emitter& out, const Eigen::Vector3d& v) {
  out << YAML::Flow << YAML::BeginSeq << num(v[0]) << num(v[1]) << num(v[2]) << YAML::EndSeq;
}

inline void emit_mat3(YAML::Emitter& out, const Eigen::Matrix3d& m) {
  out << YAML::BeginSeq;
  for (int r = 0; r < 3; ++r) emit_vec3(out, m.row(r).transpose());
  out << YAML::EndSeq;
}

}  // namespace driftless::calib::yio
