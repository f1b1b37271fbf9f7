// The time limit and progress reports of tetrahedralize (watchdog.hpp).

#include "watchdog.hpp"

#include <pthread.h>
#include <time.h>

#include <algorithm>
#include <cstdio>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess::detail {
namespace {

/// Seconds between progress reports.
constexpr double kProgressSeconds = 10.0;
/// Wall seconds between looks at the CPU time of a bounded step.
constexpr double kBoundPollSeconds = 0.1;

/// CPU seconds `clock` has counted (0 when it cannot be read).
double cpu_seconds(clockid_t clock) {
  timespec t{};
  if (clock_gettime(clock, &t) != 0) return 0.0;
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

Watchdog::Watchdog(double limit_seconds, Progress progress, std::string file)
    : m_limit(limit_seconds > 0.0 ? limit_seconds : 0.0),
      m_progress(std::move(progress)),
      m_file(std::move(file)),
      m_start(Clock::now()) {
  m_thread = std::thread([this] { run(); });
}

Watchdog::~Watchdog() {
  {
    const std::lock_guard<std::mutex> lock(m_mutex);
    m_done = true;
  }
  m_wake.notify_all();
  m_thread.join();
}

void Watchdog::run() {
  constexpr double kNever = 1e6;  // seconds: a wake-up that never comes (fits the clock's ticks)
  double next_report = m_progress ? kProgressSeconds : kNever;
  std::unique_lock<std::mutex> lock(m_mutex);
  while (!m_done) {
    double wake = next_report;
    if (m_limit > 0.0 && !m_stop.load()) wake = std::min(wake, m_limit);
    const double elapsed = std::chrono::duration<double>(Clock::now() - m_start).count();
    if (m_bound_cpu_seconds > 0.0 && !m_bound_reached)
      wake = std::min(wake, elapsed + kBoundPollSeconds);
    const auto until = m_start + std::chrono::duration_cast<Clock::duration>(
                                     std::chrono::duration<double>(std::min(wake, kNever)));
    m_wake.wait_until(lock, until, [this] { return m_done || m_changed; });
    m_changed = false;
    if (m_done) break;
    const double now = std::chrono::duration<double>(Clock::now() - m_start).count();
    if (m_limit > 0.0 && now >= m_limit) m_stop.store(true, std::memory_order_release);
    if (m_bound_cpu_seconds > 0.0 && !m_bound_reached &&
        cpu_seconds(m_bound_clock) - m_bound_cpu_start >= m_bound_cpu_seconds) {
      m_bound_reached = true;
      m_stop.store(true, std::memory_order_release);
    }
    if (now >= next_report) {
      const std::string step = m_step;
      lock.unlock();
      m_progress(now, step);
      lock.lock();
      next_report += kProgressSeconds;
    }
  }
}

void Watchdog::set_step(const std::string& step) {
  const std::lock_guard<std::mutex> lock(m_mutex);
  m_step = step;
}

double Watchdog::seconds_left() const {
  if (m_limit <= 0.0) return 1e9;
  return m_limit - std::chrono::duration<double>(Clock::now() - m_start).count();
}

void Watchdog::check() const {
  if (m_limit <= 0.0 || seconds_left() > 0.0) return;
  std::string step;
  {
    const std::lock_guard<std::mutex> lock(m_mutex);
    step = m_step;
  }
  char limit[32];
  std::snprintf(limit, sizeof limit, "%g", m_limit);
  throw TimeLimitExceeded(m_file, std::string("tetrahedralize: time limit of ") + limit +
                                      " s reached in " + (step.empty() ? "meshing" : step) +
                                      "; nothing was written (raise --time-limit, give larger "
                                      "meshing sizes, or try --repair wrap)");
}

void Watchdog::begin(const std::string& step) {
  check();
  set_step(step);
}

void Watchdog::begin_bounded(const std::string& step, double seconds) {
  check();
  {
    const std::lock_guard<std::mutex> lock(m_mutex);
    m_step = step;
    if (pthread_getcpuclockid(pthread_self(), &m_bound_clock) != 0)
      m_bound_clock = CLOCK_PROCESS_CPUTIME_ID;
    m_bound_cpu_start = cpu_seconds(m_bound_clock);
    m_bound_cpu_seconds = seconds;
    m_bound_reached = false;
    m_changed = true;
  }
  m_wake.notify_all();
}

bool Watchdog::end_bounded() {
  const std::lock_guard<std::mutex> lock(m_mutex);
  const bool reached = m_bound_reached;
  m_bound_cpu_seconds = 0.0;
  m_bound_reached = false;
  const bool limit_passed =
      m_limit > 0.0 && std::chrono::duration<double>(Clock::now() - m_start).count() >= m_limit;
  if (reached && !limit_passed) m_stop.store(false, std::memory_order_release);
  if (limit_passed) m_stop.store(true, std::memory_order_release);
  return reached;
}

}  // namespace tetseg::preprocess::detail
