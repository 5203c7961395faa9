// core::SwappedValue: a Reader sees a swap from its next current() on, keeps what it last read
// alive until then, and never sees half of a value swapped while it reads.
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <thread>

#include "serial_robot_driver/core/swapped_value.h"

namespace serial_robot_driver::core {
namespace {

struct Pair {
  Pair(long a_value, long b_value) : a(a_value), b(b_value) {}
  long a;
  long b;
};

TEST(SwappedValue, AReaderSeesASwapFromItsNextReadOn) {
  SwappedValue<Pair> value(std::make_shared<const Pair>(1, 1));
  SwappedValue<Pair>::Reader reader(value);
  EXPECT_EQ(reader.current().a, 1);
  value.set(std::make_shared<const Pair>(2, 2));
  EXPECT_EQ(reader.current().a, 2);
  EXPECT_EQ(value.get()->a, 2);
  EXPECT_EQ(reader.current().a, 2) << "unchanged without a swap";
  SwappedValue<Pair>::Reader late(value);
  EXPECT_EQ(late.current().a, 2) << "a Reader made after a swap starts from the value in force";
}

TEST(SwappedValue, WhatAReaderLastReadStaysAliveUntilItsNextRead) {
  SwappedValue<Pair> value(std::make_shared<const Pair>(1, 1));
  SwappedValue<Pair>::Reader reader(value);
  std::weak_ptr<const Pair> first = value.get();
  const Pair& read = reader.current();
  value.set(std::make_shared<const Pair>(2, 2));
  ASSERT_FALSE(first.expired()) << "the reader still holds it";
  EXPECT_EQ(read.a, 1);
  reader.current();
  EXPECT_TRUE(first.expired()) << "released once the reader has moved on";
}

TEST(SwappedValue, AValueSwappedWhileAnotherThreadReadsIsSeenWhole) {
  SwappedValue<Pair> value(std::make_shared<const Pair>(0, 0));
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (long i = 1; i <= 20000; ++i) value.set(std::make_shared<const Pair>(i, -i));
    done = true;
  });
  SwappedValue<Pair>::Reader reader(value);
  long last = 0;
  long torn = 0;
  long backwards = 0;
  while (!done) {
    const Pair& now = reader.current();
    if (now.a != -now.b) ++torn;
    if (now.a < last) ++backwards;
    last = now.a;
  }
  writer.join();
  EXPECT_EQ(torn, 0);
  EXPECT_EQ(backwards, 0);
  EXPECT_EQ(reader.current().a, 20000) << "the last swap is seen";
}

}  // namespace
}  // namespace serial_robot_driver::core
