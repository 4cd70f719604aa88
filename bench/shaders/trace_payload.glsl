// The trace benchmark's payload (trace_paths.rgen, trace_hit.rchit, trace_miss.rmiss).
struct Payload {
  float t;  // < 0: missed
  uint primitive;
};
