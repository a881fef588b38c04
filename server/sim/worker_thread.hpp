// A thread that runs one job at a time beside the thread that starts it, which waits for it when it
// needs its result. The scheduler runs the simulation's step on one (the water steps while the
// scene's passes, which need only the frame's inputs, are drawn; the job is the same code in the
// same order on whichever thread, so lockstep runs stay bit-exact), and the step itself shares its
// work with another (`dp-world`: the world outside the glass); each view's rain layer is built on
// one (`dp-rain-build`) beside the render thread, sharing its work with a second, and the spray
// pass shares its with one. Starting a job costs a wake-up, not a thread.
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace downpour::sim {

// Names a thread as `top -H`, perf and gdb show it (at most 15 characters).
void name_this_thread(const char* name);

// The cores this process may run on (taskset, a container's CPU set), not all the machine's: what
// the threads the server starts are sized by.
unsigned usable_cores();

class WorkerThread {
 public:
  // `name`: the thread's (name_this_thread).
  explicit WorkerThread(const char* name);
  ~WorkerThread();
  WorkerThread(const WorkerThread&) = delete;
  WorkerThread& operator=(const WorkerThread&) = delete;

  // Starts `job` on the thread; the previous one must have been waited for. The job must not
  // throw (catch inside it what it may throw, and keep it for whoever waits for it).
  void start(std::function<void()> job);
  // Starts `job` if the thread is idle; false (and nothing started) while a job is running.
  bool try_start(std::function<void()>& job);
  // Returns once the started job has finished (at once if none is running).
  void wait();

 private:
  void run();

  std::mutex mutex_;
  std::condition_variable cv_;
  std::function<void()> job_;  // guarded by mutex_
  bool busy_ = false;          // guarded by mutex_
  bool stopping_ = false;      // guarded by mutex_
  std::thread thread_;
};

// Waits for a worker's job when the scope it is in ends, however it ends (a throw included): for a
// job that uses the scope's locals. Waits for nothing while it has no worker.
class WaitOnExit {
 public:
  explicit WaitOnExit(WorkerThread* worker = nullptr) : worker_(worker) {}
  ~WaitOnExit() {
    if (worker_) worker_->wait();
  }
  WaitOnExit(const WaitOnExit&) = delete;
  WaitOnExit& operator=(const WaitOnExit&) = delete;
  void set(WorkerThread* worker) { worker_ = worker; }

 private:
  WorkerThread* worker_;
};

}  // namespace downpour::sim
