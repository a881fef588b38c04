#include "server/encode/encoder_pool.hpp"

#include <pthread.h>

#include <chrono>
#include <exception>

#include "server/encode/ground_truth.hpp"
#include "server/encode/jpeg_encoder.hpp"

namespace downpour::encode {
namespace {
constexpr std::size_t kMaxSpareBuffers = 16;
}

EncoderPool::EncoderPool(int threads, int max_queued) : max_queued_(max_queued) {
  for (int i = 0; i < threads; ++i) {
    workers_.emplace_back([this] {
      pthread_setname_np(pthread_self(), "dp-encode");  // (as top -H and perf show it)
      run();
    });
  }
}

EncoderPool::~EncoderPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  has_work_.notify_all();
  for (auto& w : workers_) w.join();
}

bool EncoderPool::try_reserve(int n) {
  std::lock_guard lock(mutex_);
  if (reserved_ + n > max_queued_) return false;
  reserved_ += n;
  return true;
}

void EncoderPool::release_reservation(int n) {
  std::lock_guard lock(mutex_);
  reserved_ -= n;
}

void EncoderPool::submit(EncodeJob job) {
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(job));
  }
  has_work_.notify_one();
}

void EncoderPool::set_on_idle_slot(std::function<void()> callback) {
  on_idle_slot_ = std::move(callback);
}

std::vector<std::uint8_t> EncoderPool::take_buffer(std::size_t bytes) {
  std::lock_guard lock(mutex_);
  for (auto it = spare_buffers_.begin(); it != spare_buffers_.end(); ++it) {
    if (it->capacity() >= bytes) {
      std::vector<std::uint8_t> b = std::move(*it);
      spare_buffers_.erase(it);
      b.resize(bytes);
      return b;
    }
  }
  return std::vector<std::uint8_t>(bytes);
}

void EncoderPool::release_spare_buffers() {
  std::vector<std::vector<std::uint8_t>> spare;
  {
    std::lock_guard lock(mutex_);
    spare.swap(spare_buffers_);
  }
}

void EncoderPool::run() {
  JpegEncoder encoder;
  for (;;) {
    EncodeJob job;
    {
      std::unique_lock lock(mutex_);
      has_work_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, and all work done
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    const auto t0 = std::chrono::steady_clock::now();
    EncodedImages images;
    try {
      images.jpeg = encoder.encode({job.rgba.data(), job.width, job.height}, job.quality);
      if (job.clean_jpeg)
        images.clean_jpeg = encoder.encode({job.clean.data(), job.width, job.height}, job.quality);
      if (job.water_mask)
        images.water_mask_png = water_mask_png(job.rgba, job.clean, job.width, job.height);
      if (!job.depth_m.empty()) images.depth_png = depth_png(job.depth_m, job.width, job.height);
    } catch (const std::exception&) {
      images.jpeg.clear();  // the job's owner reports the failure
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    job.done(std::move(images), ms);
    {
      std::lock_guard lock(mutex_);
      --reserved_;
      for (std::vector<std::uint8_t>* used : {&job.rgba, &job.clean}) {
        if (!used->empty() && spare_buffers_.size() < kMaxSpareBuffers)
          spare_buffers_.push_back(std::move(*used));
      }
    }
    if (on_idle_slot_) on_idle_slot_();
  }
}

}  // namespace downpour::encode
