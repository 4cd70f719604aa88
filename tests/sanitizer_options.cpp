// Sanitizer defaults for vkrt's test binaries (used only when they are built with -DVKRT_SANITIZE=ON or =thread;
// the functions are ignored otherwise). Environment variables still override them.
extern "C" {

__attribute__((visibility("default"))) const char* __asan_default_options() {
  return "detect_leaks=1:abort_on_error=0:detect_stack_use_after_return=0";
}

// use_tls=0: GCC 12's LeakSanitizer crashes ("Tracer caught signal 11") walking the dynamic TLS of a process
// whose Vulkan loader has dlclosed a library with thread-local storage; leaks are still found through the
// heap and the stacks. The suppressions cover the loader's and the validation layer's own allocations.
__attribute__((visibility("default"))) const char* __lsan_default_options() {
  return "use_tls=0:print_suppressions=0:suppressions=" VKRT_LSAN_SUPPRESSIONS;
}

// ThreadSanitizer: every report fails the test binary (exit code 66 at exit); second_deadlock_stack names both
// acquisitions of a lock-order inversion; the suppressions cover libraries built without ThreadSanitizer.
__attribute__((visibility("default"))) const char* __tsan_default_options() {
  return "second_deadlock_stack=1:report_signal_unsafe=0:suppressions=" VKRT_TSAN_SUPPRESSIONS;
}
}
