// Translation cost of the swatch over an output sub-patch, paper section 2.4, Eqs. (1)-(2):
// one work-item per (point p, offset t) writes min over faces f of
//   (1 + lambda * Dist(v_p - t, f)) * (1 + |n_p - n_f|)
// to out[t_local * num_points + p]; the host sums each offset's row in point order (Eq. 3).
// The grid traversal and the point-triangle region tests mirror core/translation_cost.cpp and
// core/point_triangle.h (Ericson, Real-Time Collision Detection 5.1.5).
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL FP_CONTRACT OFF

typedef double real;
typedef double3 real3;

// Squared distance from p to triangle (a, b, c): closest point by Voronoi region tests.
static real triangle_dist2(real3 p, real3 a, real3 b, real3 c) {
  const real3 ab = b - a, ac = c - a, ap = p - a;
  const real d1 = dot(ab, ap), d2 = dot(ac, ap);
  real u, v, w;
  if (d1 <= 0 && d2 <= 0) {
    u = 1; v = 0; w = 0;
  } else {
    const real3 bp = p - b;
    const real d3 = dot(ab, bp), d4 = dot(ac, bp);
    const real vc = d1 * d4 - d3 * d2;
    const real3 cp = p - c;
    const real d5 = dot(ab, cp), d6 = dot(ac, cp);
    const real vb = d5 * d2 - d1 * d6;
    const real va = d3 * d6 - d5 * d4;
    if (d3 >= 0 && d4 <= d3) {
      u = 0; v = 1; w = 0;
    } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
      v = d1 / (d1 - d3); u = 1 - v; w = 0;
    } else if (d6 >= 0 && d5 <= d6) {
      u = 0; v = 0; w = 1;
    } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
      w = d2 / (d2 - d6); u = 1 - w; v = 0;
    } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
      w = (d4 - d3) / ((d4 - d3) + (d5 - d6)); u = 0; v = 1 - w;
    } else {
      const real sum = va + vb + vc;
      if (!(sum > 0)) {
        // Degenerate (collinear) face: nearest vertex, as on the CPU.
        const real da = dot(ap, ap), db = dot(bp, bp), dc = dot(cp, cp);
        if (da <= db && da <= dc) {
          u = 1; v = 0; w = 0;
        } else if (db <= dc) {
          u = 0; v = 1; w = 0;
        } else {
          u = 0; v = 0; w = 1;
        }
      } else {
        const real denom = 1 / sum;
        v = vb * denom; w = vc * denom; u = 1 - v - w;
      }
    }
  }
  const real3 d = p - (u * a + v * b + w * c);
  return d.x * d.x + d.y * d.y + d.z * d.z;
}

// Distance, in cells, from continuous cell coordinate g to the slab of cell i.
static real cell_gap(real g, int i) { return fmax((real)0, fmax(i - g, g - (i + 1))); }

__kernel void translation_cost_minima(
    __global const real* points,          // #P * 3
    __global const real* point_normals,   // #P * 3
    __global const real* offsets,         // #T * 3, starting at this launch's first offset
    __global const real* entry_triangles, // #entries * 9, in cell order
    __global const real* entry_normals,   // #entries * 4: unit face normal, 0
    __global const real* entry_spheres,   // #entries * 4: centre, radius
    __global const int* cell_start,       // #cells + 1
    __global const real* cell_boxes,      // #cells * 8: box of the cell's face parts
    __global const real* cell_cones,      // #cells * 4: normal cone (direction, radius)
    const real origin_x, const real origin_y, const real origin_z, const real h,
    const int nx, const int ny, const int nz, const real lambda, const int num_points,
    __global real* out) {                  // #T * #P
  const int p = get_global_id(0);
  const int t = get_global_id(1);
  if (p >= num_points) return;
  const real3 q = vload3(p, points) - vload3(t, offsets);
  const real3 n = vload3(p, point_normals);
  const int dims[3] = {nx, ny, nz};
  const real g[3] = {(q.x - origin_x) / h, (q.y - origin_y) / h, (q.z - origin_z) / h};
  int c[3];
  for (int a = 0; a < 3; ++a) c[a] = (int)clamp(floor(g[a]), (real)0, (real)(dims[a] - 1));
  const real slack = 1e-9 * h;
  real best = INFINITY;
  for (int k = 0;; ++k) {
    if (k > 0) {
      real lb = INFINITY;
      for (int a = 0; a < 3; ++a)
        for (int s = -1; s <= 1; s += 2) {
          const int i = c[a] + s * k;
          if (i >= 0 && i < dims[a]) lb = fmin(lb, cell_gap(g[a], i));
        }
      if (lb == INFINITY) break;
      if (1 + lambda * (lb * h - slack) >= best) break;
    }
    const int x0 = max(0, c[0] - k), x1 = min(nx - 1, c[0] + k);
    const int y0 = max(0, c[1] - k), y1 = min(ny - 1, c[1] + k);
    for (int x = x0; x <= x1; ++x) {
      for (int y = y0; y <= y1; ++y) {
        const bool shell = abs(x - c[0]) == k || abs(y - c[1]) == k;
        const int z0 = shell ? max(0, c[2] - k) : 0;
        const int z1 = shell ? min(nz - 1, c[2] + k) : (k > 0 ? 1 : 0);
        for (int zi = z0; zi <= z1; ++zi) {
          const int z = shell ? zi : (zi == 0 ? c[2] - k : c[2] + k);
          if (z < 0 || z >= nz) continue;
          const int cell = (z * ny + y) * nx + x;
          const int j0 = cell_start[cell], j1 = cell_start[cell + 1];
          if (j0 == j1) continue;
          const real3 blo = vload3(0, cell_boxes + 8 * cell);
          const real3 bhi = vload3(0, cell_boxes + 8 * cell + 4);
          const real3 e = fmax((real3)(0), fmax(blo - q, q - bhi));
          const real dist_factor = 1 + lambda * (sqrt(e.x * e.x + e.y * e.y + e.z * e.z) - slack);
          if (dist_factor >= best) continue;
          const real3 dc = n - vload3(0, cell_cones + 4 * cell);
          const real cone_lb = sqrt(dc.x * dc.x + dc.y * dc.y + dc.z * dc.z) - cell_cones[4 * cell + 3];
          if (dist_factor * (1 + fmax((real)0, cone_lb)) >= best) continue;
          real r = best / dist_factor - 1;
          real r2 = r * r * (1 + 1e-12);
          for (int j = j0; j < j1; ++j) {
            const real3 dn = n - vload3(0, entry_normals + 4 * j);
            const real dn2 = dn.x * dn.x + dn.y * dn.y + dn.z * dn.z;
            if (dn2 >= r2) continue;
            const real nf = 1 + sqrt(dn2);
            const real3 ds = q - vload3(0, entry_spheres + 4 * j);
            const real sphere_lb = sqrt(ds.x * ds.x + ds.y * ds.y + ds.z * ds.z) - entry_spheres[4 * j + 3];
            if ((1 + lambda * (sphere_lb - slack)) * nf >= best) continue;
            const real d2 = triangle_dist2(q, vload3(3 * j, entry_triangles),
                                           vload3(3 * j + 1, entry_triangles),
                                           vload3(3 * j + 2, entry_triangles));
            const real cost = (1 + lambda * sqrt(d2)) * nf;
            if (cost < best) {
              best = cost;
              r = best / dist_factor - 1;
              r2 = r * r * (1 + 1e-12);
            }
          }
        }
      }
    }
  }
  out[t * num_points + p] = best;
}
