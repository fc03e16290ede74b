#include "render/frame_writer.h"

#include <utility>

namespace pr {

FrameWriter::FrameWriter() : thread_([this] { run(); }) {}

FrameWriter::~FrameWriter() {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void FrameWriter::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    cv_.wait(lock, [this] { return stop_ || next_; });
    if (!next_) return;  // stopped with nothing left to write
    std::function<void()> write = std::move(next_);
    next_ = nullptr;
    busy_ = true;
    lock.unlock();
    std::exception_ptr error;
    try {
      write();
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    busy_ = false;
    if (error && !error_) error_ = error;
    cv_.notify_all();
  }
}

void FrameWriter::idle(std::unique_lock<std::mutex>& lock) {
  cv_.wait(lock, [this] { return !busy_ && !next_; });
  if (error_) std::rethrow_exception(error_);
}

void FrameWriter::wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle(lock);
}

void FrameWriter::submit(std::function<void()> write) {
  std::unique_lock<std::mutex> lock(mutex_);
  idle(lock);
  next_ = std::move(write);
  cv_.notify_all();
}

}  // namespace pr
