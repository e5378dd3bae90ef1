// The sanitizers' options, built into every sanitized program (the tests and the
// misalloc they run), so that each runs as CI runs it without an environment of its own;
// ASAN_OPTIONS, LSAN_OPTIONS and UBSAN_OPTIONS still override them. Any finding fails:
// abort_on_error and halt_on_error. LeakSanitizer ignores what the OpenCL driver stack
// keeps until exit (tests/lsan.supp), and runs with intercept_tls_get_addr=0: with
// __tls_get_addr intercepted, its stop-the-world tracer segfaulted at exit ("Tracer
// caught signal 11", after the test had passed) on the dynamic TLS of the threads that
// PoCL and LLVM start.
extern "C" {
const char* __asan_default_options() { return "detect_leaks=1:abort_on_error=1"; }
const char* __lsan_default_options() {
  return "suppressions=" MISALLOC_LSAN_SUPPRESSIONS ":intercept_tls_get_addr=0";
}
const char* __ubsan_default_options() { return "print_stacktrace=1:halt_on_error=1"; }
}
