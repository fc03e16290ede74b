// The conformance gate's own test: a variadic macro, which OpenCL C 1.2 does not have (PoCL's
// and Intel's compilers accept it, NVIDIA's refuses it). tools/ci/kernel-conformance.sh must
// fail on line 4 of this file.
#define PR_FIXTURE_FIRST(first, ...) first

__kernel void fixture(__global int* out) {
  out[get_global_id(0)] = PR_FIXTURE_FIRST(1, 2, 3);
}
