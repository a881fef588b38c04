#include "server/app/fatal_signals.hpp"

#include <execinfo.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstring>

namespace downpour::app {
namespace {

// (GCC defines the first two; clang says it by __has_feature.)
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

// Set by the first report: a fault while it is written (another signal, or another thread's),
// dies of its signal at once.
std::atomic<bool> g_reporting{false};

constexpr int kSignals[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};

// Async-signal-safe output: write(2) of literal text and of numbers formatted by hand.
void say(const char* text) {
  std::size_t n = std::strlen(text);
  while (n > 0) {
    const ssize_t w = write(STDERR_FILENO, text, n);
    if (w <= 0) return;
    text += w;
    n -= static_cast<std::size_t>(w);
  }
}

void say_hex(std::uintptr_t value) {
  char digits[2 + 2 * sizeof value + 1];
  char* p = digits + sizeof digits - 1;
  *p = '\0';
  do {
    *--p = "0123456789abcdef"[value & 15];
    value >>= 4;
  } while (value != 0);
  *--p = 'x';
  *--p = '0';
  say(p);
}

void say_number(long value) {
  char digits[24];
  char* p = digits + sizeof digits - 1;
  *p = '\0';
  const bool negative = value < 0;
  unsigned long u = negative ? 0ul - static_cast<unsigned long>(value) : value;
  do {
    *--p = static_cast<char>('0' + u % 10);
    u /= 10;
  } while (u != 0);
  if (negative) *--p = '-';
  say(p);
}

void on_fatal_signal(int signal, siginfo_t* info, void*) {
  // One report (the same signal again meets the default action: SA_RESETHAND).
  if (g_reporting.exchange(true)) {
    ::signal(signal, SIG_DFL);
    raise(signal);
    return;
  }
  say("\nfatal signal ");
  say_number(signal);
  say(" (SIG");
  const char* abbreviation = sigabbrev_np(signal);  // a static string
  say(abbreviation ? abbreviation : "?");
  say(")");
  if (info && info->si_code > 0) {  // a fault: where
    say(" at address ");
    say_hex(reinterpret_cast<std::uintptr_t>(info->si_addr));
  } else if (info && info->si_pid == getpid()) {  // abort(), raise()
    say(" raised by the server itself");
  } else if (info) {  // sent: by whom
    say(" sent by process ");
    say_number(info->si_pid);
  }
  char name[16] = {};
  if (pthread_getname_np(pthread_self(), name, sizeof name) == 0) {
    say(" on thread ");
    say(name);
  }
  say("; backtrace:\n");
  void* frames[64];
  const int depth = backtrace(frames, 64);
  backtrace_symbols_fd(frames, depth, STDERR_FILENO);
  // Die of it as we would have: the handler was reset to the default; the signal, unblocked on
  // return, is raised again (a fault re-executes the faulting instruction).
  if (signal == SIGABRT || (info && info->si_code <= 0)) raise(signal);  // sent, not a fault
}

}  // namespace

void report_fatal_signals() {
  if (kSanitized) return;
  void* warm[1];
  backtrace(warm, 1);  // loads libgcc's unwinder now, not inside a handler
  struct sigaction action {};
  action.sa_sigaction = on_fatal_signal;
  action.sa_flags = SA_SIGINFO | SA_RESETHAND | SA_NODEFER;
  sigemptyset(&action.sa_mask);
  for (const int signal : kSignals) sigaction(signal, &action, nullptr);
}

}  // namespace downpour::app
