// The conformance gate's own test: strict OpenCL C 1.2 that the gate must pass.
#define PR_FIXTURE_FIRST(first, second) first

__kernel void fixture(__global int* out) {
  out[get_global_id(0)] = PR_FIXTURE_FIRST(1, 2);
}
