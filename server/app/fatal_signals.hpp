// A crash says where it happened: on SIGSEGV, SIGBUS, SIGFPE, SIGILL or SIGABRT the server writes
// the signal, the faulting address, the thread's name and a backtrace to stderr (the log), then
// dies of the same signal as it would have (its exit status and core dump unchanged). Frames in
// the server itself print as downpour-server(+0xOFFSET): `addr2line -f -C -e downpour-server
// 0xOFFSET` names them. Not installed under ASan or TSan, whose own reports say more.
// What it cannot report: a fault on a thread that blocks the signal (Mesa's own threads, the
// rasterizer's `llvmpipe-N` among them, block all signals: the kernel then kills the process at
// once), and a stack overflow (no alternate stack to run the handler on).
#pragma once

namespace downpour::app {

// Installs the handlers (once, before any thread starts: it also loads what backtrace() needs,
// which must not happen first inside a handler).
void report_fatal_signals();

}  // namespace downpour::app
