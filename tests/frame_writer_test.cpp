// The frame writer (host/render/frame_writer.h): frames written in the order handed over, on
// another thread, at most one behind the caller; an error surfaces at the next wait or hand-over
// and nothing is written after it; destruction writes what was handed over.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "render/frame_writer.h"

namespace pr {
namespace {

TEST(FrameWriter, WritesInOrderOnAnotherThreadOneBehind) {
  std::vector<int> order;
  std::atomic<int> inFlight{0}, most{0};
  const std::thread::id caller = std::this_thread::get_id();
  bool elsewhere = true;
  {
    FrameWriter w;
    for (int f = 0; f < 20; ++f) {
      w.wait();
      w.submit([&, f] {
        const int n = ++inFlight;
        most = std::max(most.load(), n);
        if (std::this_thread::get_id() == caller) elsewhere = false;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        order.push_back(f);
        --inFlight;
      });
    }
    w.wait();
    EXPECT_EQ(order.size(), 20u);
  }
  for (int f = 0; f < 20; ++f) EXPECT_EQ(order[size_t(f)], f);
  EXPECT_EQ(most.load(), 1);
  EXPECT_TRUE(elsewhere);
}

TEST(FrameWriter, AnErrorStopsTheWritesAfterIt) {
  std::vector<int> written;
  FrameWriter w;
  w.submit([&] { written.push_back(0); });
  w.submit([&]() { throw std::runtime_error("disk full"); });
  EXPECT_THROW({ w.wait(); }, std::runtime_error);
  EXPECT_THROW(w.submit([&] { written.push_back(2); }), std::runtime_error);
  EXPECT_THROW(w.wait(), std::runtime_error);  // it stays failed
  EXPECT_EQ(written, std::vector<int>{0});
}

TEST(FrameWriter, DestructionWritesWhatWasHandedOver) {
  std::atomic<bool> done{false};
  {
    FrameWriter w;
    w.submit([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      done = true;
    });
  }
  EXPECT_TRUE(done.load());
}

}  // namespace
}  // namespace pr
