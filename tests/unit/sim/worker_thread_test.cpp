// A worker thread (the step's, the CPU layers' helpers): its jobs run one at a time, and it carries
// the name it was given (what `top -H` and perf show), cut to the 15 characters a thread name
// holds.
#include "server/sim/worker_thread.hpp"

#include <pthread.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace downpour::sim {
namespace {

std::string name_on(WorkerThread& worker) {
  std::string name;
  worker.start([&name] {
    char buffer[16] = {};
    pthread_getname_np(pthread_self(), buffer, sizeof buffer);
    name = buffer;
  });
  worker.wait();
  return name;
}

TEST(WorkerThreadTest, RunsItsJobsUnderItsName) {
  WorkerThread worker("dp-test");
  EXPECT_EQ(name_on(worker), "dp-test");
  int sum = 0;
  for (int i = 1; i <= 3; ++i) {
    worker.start([&sum, i] { sum += i; });
    worker.wait();
  }
  EXPECT_EQ(sum, 6);
}

TEST(WorkerThreadTest, TryStartStartsOnlyWhenIdle) {
  WorkerThread worker("dp-test");
  std::atomic<bool> release{false};
  worker.start([&release] {
    while (!release.load()) std::this_thread::yield();
  });
  int ran = 0;
  std::function<void()> job = [&ran] { ++ran; };
  EXPECT_FALSE(worker.try_start(job));
  EXPECT_TRUE(job);  // not taken
  release = true;
  worker.wait();
  EXPECT_TRUE(worker.try_start(job));
  worker.wait();
  EXPECT_EQ(ran, 1);
}

TEST(WorkerThreadTest, WaitOnExitWaitsForTheJobWhenAThrowEndsTheScope) {
  WorkerThread worker("dp-test");
  std::atomic<bool> done{false};
  try {
    worker.start([&done] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      done = true;
    });
    const WaitOnExit waits(&worker);
    throw std::runtime_error("the scope ends");
  } catch (const std::runtime_error&) {
    EXPECT_TRUE(done.load());
  }
}

TEST(WorkerThreadTest, ALongNameIsCutToWhatAThreadHolds) {
  // (Built where the worker is made and gone after: the thread keeps its own copy.)
  WorkerThread worker(std::string("dp-a-name-longer-than-fifteen").c_str());
  EXPECT_EQ(name_on(worker), std::string("dp-a-name-longer-than-fifteen").substr(0, 15));
}

}  // namespace
}  // namespace downpour::sim
