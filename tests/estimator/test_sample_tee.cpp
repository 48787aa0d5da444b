// The tee that lets a second pass read the rows the first pass reads (estimator/sample_tee.hpp):
// every row in order once attached early enough, none kept past its bound, and no side left
// waiting for the other when one stops.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <thread>

#include <gtest/gtest.h>

#include "estimator/sample_tee.hpp"

namespace driftless::est {
namespace {

Sample row(std::size_t i) {
  Sample s;
  s.t_s = 0.01 * static_cast<double>(i);
  s.gyro1_dps.x() = static_cast<double>(i);
  return s;
}

// GIVEN rows offered before the second pass attaches (fewer than the bound) and many after
// WHEN it attaches and reads beside the producer THEN it gets every row once, in order, although
// the producer offers four times the bound (it waits for the reader: the queue stays bounded)
TEST(SampleTee, ASecondPassAttachedEarlyGetsEveryRowInOrder) {
  SampleTee tee;
  const std::size_t before = SampleTee::kMaxSamples / 2, total = 4 * SampleTee::kMaxSamples + 17;
  for (std::size_t i = 0; i < before; ++i) tee.offer(row(i));
  ASSERT_TRUE(tee.attach());
  EXPECT_TRUE(tee.attached());
  std::size_t got = 0;
  bool in_order = true;
  std::thread reader([&] {
    Sample s;
    while (tee.next(s)) {
      in_order = in_order && s.gyro1_dps.x() == static_cast<double>(got);
      ++got;
    }
  });
  for (std::size_t i = before; i < total; ++i) tee.offer(row(i));
  tee.end();
  reader.join();
  EXPECT_EQ(got, total);
  EXPECT_TRUE(in_order);
}

// GIVEN more rows than the bound before anyone attaches THEN the tee turns off (the rows are not
// kept), attach() says so and the producer goes on without waiting
TEST(SampleTee, TooManyRowsBeforeTheSecondPassTurnTheTeeOff) {
  SampleTee tee;
  for (std::size_t i = 0; i < SampleTee::kMaxSamples + SampleTee::kChunk; ++i) tee.offer(row(i));
  EXPECT_FALSE(tee.attach());
  EXPECT_FALSE(tee.attached());
  for (std::size_t i = 0; i < 3 * SampleTee::kMaxSamples; ++i) tee.offer(row(i));  // would block if queued
  tee.end();
  Sample s;
  EXPECT_FALSE(tee.next(s));
}

// GIVEN an attached reader that stops after a few rows (abandoned, or failed) and detaches
// THEN the producer, which would otherwise wait for it at the bound, runs to its end
TEST(SampleTee, AReaderThatStopsDoesNotHoldTheProducer) {
  SampleTee tee;
  ASSERT_TRUE(tee.attach());
  std::atomic<bool> producer_done{false};
  std::thread producer([&] {
    for (std::size_t i = 0; i < 5 * SampleTee::kMaxSamples; ++i) tee.offer(row(i));
    tee.end();
    producer_done = true;
  });
  Sample s;
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(tee.next(s));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(producer_done.load());  // held at the bound
  tee.detach();
  producer.join();
  EXPECT_TRUE(producer_done.load());
  EXPECT_FALSE(tee.next(s));
}

// GIVEN a producer that fails (detaches) while an attached reader waits for rows THEN the reader's
// next() ends instead of waiting for ever
TEST(SampleTee, AFailingProducerEndsTheReader) {
  SampleTee tee;
  ASSERT_TRUE(tee.attach());
  std::thread reader([&] {
    Sample s;
    while (tee.next(s)) {
    }
  });
  for (std::size_t i = 0; i < 10; ++i) tee.offer(row(i));
  tee.detach();
  reader.join();
  SUCCEED();
}

}  // namespace
}  // namespace driftless::est
