// Finished frames written on a thread of their own while the next frame renders, so that the
// device is not left idle while the host encodes and writes a frame's EXR, PNG, resume history
// and stats line (on a GPU that was most of a 720p frame's wall time). One frame is written at
// a time, in order; at most one waits behind it, which bounds the images held to two.
#pragma once

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace pr {

class FrameWriter {
 public:
  FrameWriter();
  // Waits for the frame being written; an error it met is dropped (call wait() to see it).
  ~FrameWriter();
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  // Waits until every frame handed over is written; throws the error one met (after which
  // nothing more is written).
  void wait();
  // Hands over the writing of one frame, once the frames before it are written (wait()).
  void submit(std::function<void()> write);

 private:
  void run();
  // Waits, holding `lock`, until nothing is being written or waiting; throws a write's error.
  void idle(std::unique_lock<std::mutex>& lock);

  std::mutex mutex_;
  std::condition_variable cv_;
  std::function<void()> next_;  // handed over, not started
  bool busy_ = false;           // a frame is being written
  bool stop_ = false;
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace pr
