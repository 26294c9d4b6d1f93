// Per-tet L2 stretch of the shell map, paper section 3.2, Eq. (8), with J = d(shell) /
// d(texture) (see core/shell/tet_stretch.h for the convention): one work-item per tet. The closed
// form mirrors stretch_closed_form in core/shell/tet_stretch.cpp operation for operation.
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL FP_CONTRACT OFF

typedef double real;

__kernel void tet_stretch(__global const real* shell_V,    // #V * 3
                          __global const real* texture_V,  // #V * 3
                          __global const int* tets,        // #T * 4
                          const int num_tets,
                          __global real* out) {             // #T
  const int t = get_global_id(0);
  if (t >= num_tets) return;
  const int v0 = tets[4 * t], v1 = tets[4 * t + 1], v2 = tets[4 * t + 2], v3 = tets[4 * t + 3];
  real e[3][3], q[3][3];
  for (int a = 0; a < 3; ++a) {
    const real s0 = shell_V[3 * v0 + a], t0 = texture_V[3 * v0 + a];
    e[0][a] = shell_V[3 * v1 + a] - s0;
    e[1][a] = shell_V[3 * v2 + a] - s0;
    e[2][a] = shell_V[3 * v3 + a] - s0;
    q[0][a] = texture_V[3 * v1 + a] - t0;
    q[1][a] = texture_V[3 * v2 + a] - t0;
    q[2][a] = texture_V[3 * v3 + a] - t0;
  }
  real r[3][3];
  const int i1[3] = {1, 2, 0}, i2[3] = {2, 0, 1};
  for (int m = 0; m < 3; ++m) {
    const int j1 = i1[m], j2 = i2[m];
    r[m][0] = q[j1][1] * q[j2][2] - q[j1][2] * q[j2][1];
    r[m][1] = q[j1][2] * q[j2][0] - q[j1][0] * q[j2][2];
    r[m][2] = q[j1][0] * q[j2][1] - q[j1][1] * q[j2][0];
  }
  const real det_t = q[0][0] * r[0][0] + q[0][1] * r[0][1] + q[0][2] * r[0][2];
  const real det_s = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) +
                     e[0][1] * (e[1][2] * e[2][0] - e[1][0] * e[2][2]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
  if (!(det_t * det_s > 0)) {
    out[t] = INFINITY;
    return;
  }
  real sum = 0;
  for (int k = 0; k < 3; ++k) {
    for (int a = 0; a < 3; ++a) {
      const real c = e[0][a] * r[0][k] + e[1][a] * r[1][k] + e[2][a] * r[2][k];
      sum += c * c;
    }
  }
  out[t] = sqrt(sum / (det_t * det_t) / 3);
}
