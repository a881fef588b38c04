#include "server/sim/worker_thread.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

namespace downpour::sim {

void name_this_thread(const char* name) {
  char shortened[16] = {};
  std::strncpy(shortened, name, sizeof shortened - 1);
  pthread_setname_np(pthread_self(), shortened);
}

unsigned usable_cores() {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  return sched_getaffinity(0, sizeof allowed, &allowed) == 0
             ? static_cast<unsigned>(CPU_COUNT(&allowed))
             : std::max(1u, std::thread::hardware_concurrency());
}

WorkerThread::WorkerThread(const char* name)
    : thread_([this, name = std::string(name)] {  // (a copy: the thread may start after we return)
        name_this_thread(name.c_str());
        run();
      }) {}

WorkerThread::~WorkerThread() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void WorkerThread::start(std::function<void()> job) {
  {
    std::lock_guard lock(mutex_);
    if (busy_) throw std::logic_error("WorkerThread::start while a job is running");
    job_ = std::move(job);
    busy_ = true;
  }
  cv_.notify_all();
}

bool WorkerThread::try_start(std::function<void()>& job) {
  {
    std::lock_guard lock(mutex_);
    if (busy_) return false;
    job_ = std::move(job);
    busy_ = true;
  }
  cv_.notify_all();
  return true;
}

void WorkerThread::wait() {
  std::unique_lock lock(mutex_);
  cv_.wait(lock, [this] { return !busy_; });
}

void WorkerThread::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    cv_.wait(lock, [this] { return stopping_ || job_; });
    if (!job_) return;  // stopping, nothing left to run
    std::function<void()> job = std::move(job_);
    job_ = nullptr;
    lock.unlock();
    job();  // noexcept by contract: a job that throws ends the process here
    lock.lock();
    busy_ = false;
    cv_.notify_all();
  }
}

}  // namespace downpour::sim
