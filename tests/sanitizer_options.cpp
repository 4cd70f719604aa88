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
// intercept_tls_get_addr=0: on a thread's first access to a dlopened library's thread-local block (vkrt's and LLVM's:
// the loader dlopens libvkrt.so), GCC 12's runtime takes a block that lies 16 bytes into a page for one with a glibc
// 2.19 header in front and reads its size from the 16 bytes before it (sanitizer_tls_get_addr.cpp). Where malloc
// placed the block so (a matter of the process's layout, hence the same for one command line and environment size),
// it took that garbage (135 TB, 2026-12-07) for the block's size, reset the shadow of the whole range and stopped the
// test: "ThreadSanitizer failed to allocate 0x1ed40000bf000 bytes ... (errno: 12)" (one to three of 926 tests a run).
// Glibc 2.36 allocates these blocks with malloc, whose interceptor gives a new block fresh shadow: nothing is lost.
__attribute__((visibility("default"))) const char* __tsan_default_options() {
  return "second_deadlock_stack=1:report_signal_unsafe=0:intercept_tls_get_addr=0:suppressions=" VKRT_TSAN_SUPPRESSIONS;
}
}
