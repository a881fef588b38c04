// Encoder workers: JPEG-encode finished pixels off the render thread, so that rendering frame N+1
// overlaps encoding frame N. The queue is bounded; the render thread reserves room before it
// renders.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace downpour::encode {

// A frame's files: its JPEG and the ground truth it asked for (empty where not).
struct EncodedImages {
  std::string jpeg;
  std::string clean_jpeg;
  std::string water_mask_png;
  std::string depth_png;
};

struct EncodeJob {
  std::vector<std::uint8_t> rgba;  // bottom-up rows
  int width = 0;
  int height = 0;
  int quality = 85;
  // Ground truth: the clean frame (RGBA8, bottom-up rows, as rgba) and what to make of it, and the
  // depth in metres (bottom-up rows); empty, none.
  std::vector<std::uint8_t> clean;
  bool clean_jpeg = false;
  bool water_mask = false;
  std::vector<float> depth_m;
  // Runs on the worker with the files (jpeg empty on any failure) and the encode time.
  std::function<void(EncodedImages images, double encode_ms)> done;
};

class EncoderPool {
 public:
  EncoderPool(int threads, int max_queued);
  ~EncoderPool();  // finishes queued jobs, then joins
  EncoderPool(const EncoderPool&) = delete;
  EncoderPool& operator=(const EncoderPool&) = delete;

  // Reserves room for n jobs; false if the queue has no room for them now.
  bool try_reserve(int n);
  // Gives back reserved places that will not be used.
  void release_reservation(int n);
  // Submits into a reserved place.
  void submit(EncodeJob job);
  // Called after each finished job, on the worker (the render loop wakes on it).
  void set_on_idle_slot(std::function<void()> callback);

  int threads() const { return static_cast<int>(workers_.size()); }
  // Pixel buffers come back here after encoding, so that steady state allocates none.
  std::vector<std::uint8_t> take_buffer(std::size_t bytes);
  // Frees the buffers kept for reuse (after sessions close: their sizes may not come back).
  void release_spare_buffers();

 private:
  void run();

  const int max_queued_;
  std::mutex mutex_;
  std::condition_variable has_work_;
  std::deque<EncodeJob> queue_;  // guarded by mutex_
  int reserved_ = 0;             // guarded by mutex_: reserved + queued + running
  bool stopping_ = false;        // guarded by mutex_
  std::vector<std::vector<std::uint8_t>> spare_buffers_;  // guarded by mutex_
  std::function<void()> on_idle_slot_;                    // set before jobs run
  std::vector<std::thread> workers_;
};

}  // namespace downpour::encode
