// The one input-error type: where (file, line, key) and what, in one line a user can act on.
#include <gtest/gtest.h>

#include <stdexcept>

#include "estimator/input_error.hpp"

namespace driftless {
namespace {

TEST(InputError, NamesFileLineKeyAndDetail) {
  const InputError e("model.yaml", 12, "model.box.end_stop_deg", "expected a number, got 'x'");
  EXPECT_STREQ(e.what(), "model.yaml:12: model.box.end_stop_deg: expected a number, got 'x'");
  EXPECT_EQ(e.file(), "model.yaml");
  EXPECT_EQ(e.line(), 12u);
  EXPECT_EQ(e.key(), "model.box.end_stop_deg");
  EXPECT_EQ(e.detail(), "expected a number, got 'x'");
}

TEST(InputError, LeavesOutAbsentParts) {
  EXPECT_STREQ(InputError("log.csv", 0, "", "no such file").what(), "log.csv: no such file");
  EXPECT_STREQ(InputError("", 0, "seed", "expected an integer").what(), "seed: expected an integer");
  EXPECT_STREQ(InputError("", 3, "", "broken").what(), "line 3: broken");
}

TEST(InputError, IsAnInvalidArgumentSoValidateCallersKeepWorking) {
  try {
    throw InputError("a.yaml", 1, "k", "bad");
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "a.yaml:1: k: bad");
    return;
  }
  FAIL() << "not caught as std::invalid_argument";
}

TEST(InputError, CopiesKeepTheParts) {
  const InputError a("f", 2, "k", "d");
  const InputError b = a;  // NOLINT: the copy is the point
  EXPECT_EQ(b.file(), "f");
  EXPECT_EQ(b.line(), 2u);
  EXPECT_STREQ(b.what(), a.what());
}

TEST(InputError, WithLocationAddsFileAndLineToValidateMessages) {
  try {
    with_location("s.yaml", 4, "motion", [] { throw std::invalid_argument("max_rate_dps must be > 0"); });
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "s.yaml:4: motion: max_rate_dps must be > 0");
  }
  // an InputError inside passes unchanged (it already knows where it is)
  try {
    with_location("outer.yaml", 1, "", [] { throw InputError("inner.csv", 7, "", "bad row"); });
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "inner.csv");
    EXPECT_EQ(e.line(), 7u);
  }
  EXPECT_EQ(with_location("f", 0, "", [] { return 42; }), 42);
}

}  // namespace
}  // namespace driftless
