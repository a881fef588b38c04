#include "server/encode/encoder_pool.hpp"

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <turbojpeg.h>

#include "server/encode/jpeg_encoder.hpp"

namespace downpour::encode {
namespace {

constexpr int kWidth = 64;
constexpr int kHeight = 32;

// RGBA, bottom-up rows as GL reads them: red grows to the right, green upwards, blue constant.
std::vector<std::uint8_t> gradient(int width, int height) {
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(width) * height * 4);
  for (int row = 0; row < height; ++row) {  // row 0 is the bottom
    for (int x = 0; x < width; ++x) {
      std::uint8_t* p = &rgba[(static_cast<std::size_t>(row) * width + x) * 4];
      p[0] = static_cast<std::uint8_t>(x * 255 / (width - 1));
      p[1] = static_cast<std::uint8_t>(row * 255 / (height - 1));
      p[2] = 96;
      p[3] = 255;
    }
  }
  return rgba;
}

// Decodes to RGBA in the same bottom-up row order; empty on failure.
std::vector<std::uint8_t> decode(const std::string& jpeg, int* width, int* height) {
  tjhandle handle = tjInitDecompress();
  std::vector<std::uint8_t> out;
  int subsampling = 0;
  int colorspace = 0;
  const auto* data = reinterpret_cast<const unsigned char*>(jpeg.data());
  if (tjDecompressHeader3(handle, data, jpeg.size(), width, height, &subsampling, &colorspace) ==
      0) {
    out.resize(static_cast<std::size_t>(*width) * *height * 4);
    if (tjDecompress2(handle, data, jpeg.size(), out.data(), *width, 0, *height, TJPF_RGBA,
                      TJFLAG_BOTTOMUP) != 0) {
      out.clear();
    }
  }
  tjDestroy(handle);
  return out;
}

void expect_close_to(const std::vector<std::uint8_t>& original, const std::string& jpeg) {
  ASSERT_GE(jpeg.size(), 4u);
  EXPECT_EQ(static_cast<unsigned char>(jpeg[0]), 0xFF);
  EXPECT_EQ(static_cast<unsigned char>(jpeg[1]), 0xD8);
  EXPECT_EQ(static_cast<unsigned char>(jpeg[jpeg.size() - 2]), 0xFF);
  EXPECT_EQ(static_cast<unsigned char>(jpeg[jpeg.size() - 1]), 0xD9);
  int width = 0;
  int height = 0;
  const std::vector<std::uint8_t> decoded = decode(jpeg, &width, &height);
  ASSERT_FALSE(decoded.empty());
  EXPECT_EQ(width, kWidth);
  EXPECT_EQ(height, kHeight);
  ASSERT_EQ(decoded.size(), original.size());
  double error[3] = {0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < original.size(); i += 4) {
    for (int c = 0; c < 3; ++c) error[c] += std::abs(int(decoded[i + c]) - int(original[i + c]));
  }
  const double pixels = static_cast<double>(kWidth) * kHeight;
  for (int c = 0; c < 3; ++c) EXPECT_LT(error[c] / pixels, 8.0) << "channel " << c;
}

TEST(JpegEncoderTest, GradientDecodesToTheSameImage) {
  const std::vector<std::uint8_t> rgba = gradient(kWidth, kHeight);
  JpegEncoder encoder;
  const std::string jpeg = encoder.encode({rgba.data(), kWidth, kHeight}, 90);
  expect_close_to(rgba, jpeg);
  // The encoder is reusable.
  EXPECT_EQ(encoder.encode({rgba.data(), kWidth, kHeight}, 90), jpeg);
}

TEST(JpegEncoderTest, RowsKeepTheirOrder) {
  // Green grows upwards in the bottom-up input; decoded top-down, the first row is the greenest.
  const std::vector<std::uint8_t> rgba = gradient(kWidth, kHeight);
  JpegEncoder encoder;
  const std::string jpeg = encoder.encode({rgba.data(), kWidth, kHeight}, 90);
  tjhandle handle = tjInitDecompress();
  std::vector<std::uint8_t> top_down(rgba.size());
  ASSERT_EQ(tjDecompress2(handle, reinterpret_cast<const unsigned char*>(jpeg.data()), jpeg.size(),
                          top_down.data(), kWidth, 0, kHeight, TJPF_RGBA, 0),
            0);
  tjDestroy(handle);
  const std::size_t last_row = static_cast<std::size_t>(kHeight - 1) * kWidth * 4;
  EXPECT_GT(top_down[1], 230);
  EXPECT_LT(top_down[last_row + 1], 25);
}

TEST(JpegEncoderTest, LowerQualityIsSmaller) {
  const std::vector<std::uint8_t> rgba = gradient(kWidth, kHeight);
  JpegEncoder encoder;
  EXPECT_LT(encoder.encode({rgba.data(), kWidth, kHeight}, 10).size(),
            encoder.encode({rgba.data(), kWidth, kHeight}, 100).size());
}

TEST(EncoderPoolTest, ReservationsRespectTheBound) {
  EncoderPool pool(1, 4);
  EXPECT_EQ(pool.threads(), 1);
  EXPECT_TRUE(pool.try_reserve(3));
  EXPECT_FALSE(pool.try_reserve(2));
  EXPECT_TRUE(pool.try_reserve(1));
  EXPECT_FALSE(pool.try_reserve(1));
  pool.release_reservation(2);
  EXPECT_FALSE(pool.try_reserve(3));
  EXPECT_TRUE(pool.try_reserve(2));
  EXPECT_FALSE(pool.try_reserve(1));
  pool.release_reservation(4);
  EXPECT_FALSE(pool.try_reserve(5));
  EXPECT_TRUE(pool.try_reserve(4));
  pool.release_reservation(4);
}

TEST(EncoderPoolTest, EveryJobCompletesOnceAndFreesItsPlace) {
  constexpr int kJobs = 40;
  const std::vector<std::uint8_t> rgba = gradient(kWidth, kHeight);
  std::atomic<int> done{0};
  std::atomic<int> good{0};
  std::atomic<int> idle_calls{0};
  std::mutex mutex;
  std::vector<int> seen(kJobs, 0);
  {
    EncoderPool pool(2, 8);
    pool.set_on_idle_slot([&] { ++idle_calls; });
    for (int i = 0; i < kJobs; ++i) {
      // Wait for room, as the render thread does.
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (!pool.try_reserve(1)) {
        ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "no room came back";
        std::this_thread::yield();
      }
      EncodeJob job;
      job.rgba = pool.take_buffer(rgba.size());
      ASSERT_EQ(job.rgba.size(), rgba.size());
      std::copy(rgba.begin(), rgba.end(), job.rgba.begin());
      job.width = kWidth;
      job.height = kHeight;
      job.quality = 80;
      job.done = [&, i](EncodedImages images, double encode_ms) {
        const std::string& jpeg = images.jpeg;
        {
          std::lock_guard lock(mutex);
          ++seen[i];
        }
        if (jpeg.size() > 4 && static_cast<unsigned char>(jpeg[0]) == 0xFF && encode_ms >= 0.0) {
          ++good;
        }
        ++done;
      };
      pool.submit(std::move(job));
    }
  }  // the destructor waits for the queued jobs
  EXPECT_EQ(done.load(), kJobs);
  EXPECT_EQ(good.load(), kJobs);
  EXPECT_EQ(idle_calls.load(), kJobs);
  for (int i = 0; i < kJobs; ++i) EXPECT_EQ(seen[i], 1) << "job " << i;
}

TEST(EncoderPoolTest, DestructorFinishesQueuedJobs) {
  constexpr int kJobs = 12;
  const std::vector<std::uint8_t> rgba = gradient(kWidth, kHeight);
  std::atomic<int> done{0};
  std::atomic<bool> release{false};
  {
    EncoderPool pool(1, kJobs);
    ASSERT_TRUE(pool.try_reserve(kJobs));
    for (int i = 0; i < kJobs; ++i) {
      EncodeJob job;
      job.rgba = rgba;
      job.width = kWidth;
      job.height = kHeight;
      job.done = [&, i](EncodedImages, double) {
        // The first job holds the worker until every job is queued.
        while (i == 0 && !release.load()) std::this_thread::yield();
        ++done;
      };
      pool.submit(std::move(job));
    }
    EXPECT_LT(done.load(), kJobs);
    release.store(true);
  }
  EXPECT_EQ(done.load(), kJobs);
}

TEST(EncoderPoolTest, FinishedJobsGiveTheirRoomBack) {
  const std::vector<std::uint8_t> rgba = gradient(kWidth, kHeight);
  EncoderPool pool(1, 2);
  std::atomic<int> done{0};
  for (int round = 0; round < 5; ++round) {
    ASSERT_TRUE(pool.try_reserve(2)) << "round " << round;
    for (int i = 0; i < 2; ++i) {
      EncodeJob job;
      job.rgba = rgba;
      job.width = kWidth;
      job.height = kHeight;
      job.done = [&](EncodedImages, double) { ++done; };
      pool.submit(std::move(job));
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!pool.try_reserve(2)) {
      ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "round " << round;
      std::this_thread::yield();
    }
    pool.release_reservation(2);
  }
  // The room comes back after done returns, so done has run for every job by now.
  EXPECT_EQ(done.load(), 10);
}

TEST(EncoderPoolTest, BuffersAreRecycled) {
  const std::vector<std::uint8_t> rgba = gradient(kWidth, kHeight);
  std::atomic<int> done{0};
  const std::uint8_t* first_data = nullptr;
  {
    EncoderPool pool(1, 1);
    ASSERT_TRUE(pool.try_reserve(1));
    EncodeJob job;
    job.rgba = pool.take_buffer(rgba.size());
    first_data = job.rgba.data();
    std::copy(rgba.begin(), rgba.end(), job.rgba.begin());
    job.width = kWidth;
    job.height = kHeight;
    job.done = [&](EncodedImages, double) { ++done; };
    pool.submit(std::move(job));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!pool.try_reserve(1)) {
      ASSERT_LT(std::chrono::steady_clock::now(), deadline);
      std::this_thread::yield();
    }
    // A smaller request reuses the returned buffer.
    const std::vector<std::uint8_t> again = pool.take_buffer(rgba.size() / 2);
    EXPECT_EQ(again.data(), first_data);
    EXPECT_EQ(again.size(), rgba.size() / 2);
    pool.release_reservation(1);
  }
  EXPECT_EQ(done.load(), 1);
}

}  // namespace
}  // namespace downpour::encode
