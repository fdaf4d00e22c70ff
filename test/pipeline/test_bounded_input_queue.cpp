// The nodelet's input queue: FIFO, drops (and returns) the oldest when full, the consumer
// wakes on an item, on Wake() and on Close(), and times out otherwise.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "ipm_road_mapper/pipeline/bounded_input_queue.h"

namespace ipm_road_mapper {
namespace {

using Queue = BoundedInputQueue<int>;
using std::chrono::milliseconds;

TEST(BoundedInputQueue, FifoAndDropsTheOldestWhenFull) {
  Queue queue(3);
  EXPECT_FALSE(queue.Push(1).has_value());
  EXPECT_FALSE(queue.Push(2).has_value());
  EXPECT_FALSE(queue.Push(3).has_value());
  const std::optional<int> dropped = queue.Push(4);
  ASSERT_TRUE(dropped.has_value());
  EXPECT_EQ(*dropped, 1);
  EXPECT_EQ(queue.size(), 3u);
  int item = 0;
  for (int expected : {2, 3, 4}) {
    ASSERT_TRUE(queue.PopUntil(Queue::Clock::now(), &item));
    EXPECT_EQ(item, expected);
  }
  EXPECT_FALSE(queue.PopUntil(Queue::Clock::now(), &item));
}

TEST(BoundedInputQueue, ConsumerTimesOutWithoutItems) {
  Queue queue(2);
  int item = 0;
  const auto start = Queue::Clock::now();
  EXPECT_FALSE(queue.PopUntil(start + milliseconds(50), &item));
  EXPECT_GE(Queue::Clock::now() - start, milliseconds(45));
}

TEST(BoundedInputQueue, ConsumerWakesOnPushWakeAndClose) {
  Queue queue(2);
  int item = 0;
  const auto far = Queue::Clock::now() + std::chrono::seconds(30);
  std::thread producer([&] {
    std::this_thread::sleep_for(milliseconds(20));
    queue.Push(7);
  });
  EXPECT_TRUE(queue.PopUntil(far, &item));
  EXPECT_EQ(item, 7);
  producer.join();

  const auto start = Queue::Clock::now();
  std::thread waker([&] {
    std::this_thread::sleep_for(milliseconds(20));
    queue.Wake();
  });
  EXPECT_FALSE(queue.PopUntil(far, &item));
  EXPECT_LT(Queue::Clock::now() - start, std::chrono::seconds(5));
  waker.join();

  queue.Wake();  // a wake before the wait is not lost
  EXPECT_FALSE(queue.PopUntil(far, &item));

  queue.Push(8);
  queue.Close();
  EXPECT_FALSE(queue.Push(9).has_value());  // ignored after Close
  EXPECT_TRUE(queue.PopUntil(far, &item));  // what was queued is still drained
  EXPECT_EQ(item, 8);
  EXPECT_FALSE(queue.PopUntil(far, &item));  // closed and empty: at once
}

}  // namespace
}  // namespace ipm_road_mapper
