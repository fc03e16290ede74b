// Test kernel: y[i] = a * x[i] + y[i] for i < n. Reads x, y; writes y.
__kernel void saxpy(float a, __global const float* x, __global float* y, uint n) {
  const uint i = (uint)get_global_id(0);
  if (i >= n) return;
  y[i] = a * x[i] + y[i];
}
