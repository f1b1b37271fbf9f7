#pragma once
// Private: the time limit and progress reports of tetrahedralize (MeshingOptions::time_limit,
// ::progress). A thread sleeps until the limit or the next report; at the limit it raises the
// stop flag that CGAL Mesh_3 polls (mesh_3_options pointer_to_stop_atomic_boolean), and the
// steps that cannot be stopped are checked between them (check).

#include <time.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

namespace tetseg::preprocess::detail {

class Watchdog {
 public:
  using Progress = std::function<void(double seconds, const std::string& step)>;
  /// Starts timing (and the thread); `limit_seconds` 0: no limit.
  Watchdog(double limit_seconds, Progress progress, std::string file);
  ~Watchdog();
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  /// Names the step now running (in progress reports and the time-limit message).
  void set_step(const std::string& step);
  /// The flag CGAL polls: true once the limit has passed.
  std::atomic<bool>* stop_flag() { return &m_stop; }
  /// Seconds left before the limit (a large number without one; may be negative).
  double seconds_left() const;
  /// Throws TimeLimitExceeded("tetrahedralize: time limit of N s reached in <step> ...")
  /// naming the file when the limit has passed.
  void check() const;
  /// check(), then set_step(step).
  void begin(const std::string& step);
  /// begin(step), and the stop flag is also raised once the calling thread has run `seconds`
  /// of CPU time from now (a bound on one step that may not end, which the load of other
  /// processes does not move as it moves wall time: end_bounded says whether it was reached).
  void begin_bounded(const std::string& step, double seconds);
  /// Ends the bound of begin_bounded; true when it was reached (the stop flag is lowered
  /// again unless the limit has passed too).
  bool end_bounded();

 private:
  void run();
  using Clock = std::chrono::steady_clock;
  const double m_limit;
  const Progress m_progress;
  const std::string m_file;
  const Clock::time_point m_start;
  std::atomic<bool> m_stop{false};
  mutable std::mutex m_mutex;
  std::condition_variable m_wake;
  bool m_done = false;
  bool m_changed = false;  ///< wakes the thread to recompute its next wake-up
  // begin_bounded's bound: CPU seconds of the thread that began it (m_bound_clock) from
  // m_bound_cpu_start; 0: none.
  double m_bound_cpu_seconds = 0.0;
  double m_bound_cpu_start = 0.0;
  clockid_t m_bound_clock = CLOCK_PROCESS_CPUTIME_ID;
  bool m_bound_reached = false;
  std::string m_step;
  std::thread m_thread;
};

}  // namespace tetseg::preprocess::detail
