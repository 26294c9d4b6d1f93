// Translation cost of the swatch over an output sub-patch, paper section 2.4, Eqs. (1)-(2):
// one work-item per (point p, offset t) writes min over faces f of
//   (1 + lambda * Dist(v_p - t, f)) * (1 + |n_p - n_f|)
// to out[t_local * num_points + p]; the host sums each offset's row in point order (Eq. 3).
// The tree traversal and the point-triangle region tests mirror core/planar/translation_cost.cpp
// and core/mesh/point_triangle.h (Ericson, Real-Time Collision Detection 5.1.5); the CPU path
// scans a leaf in blocks (normal bound first), which examines the same entries as the scan here.
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

// Squared distance from q to a node's box.
static real box_distance2(real3 q, __global const real* box) {
  const real3 e = fmax((real3)(0), fmax(vload3(0, box) - q, q - vload3(0, box + 4)));
  return e.x * e.x + e.y * e.y + e.z * e.z;
}

#define MAX_STACK 50  // SwatchFaceTree::kMaxDepth + 2

__kernel void translation_cost_minima(
    __global const real* points,          // #P * 3
    __global const real* point_normals,   // #P * 3
    __global const real* offsets,         // #T * 3, starting at this launch's first offset
    __global const real* entry_triangles, // #F * 9, in leaf order
    __global const real* entry_normals,   // #F * 4: unit face normal, 0
    __global const real* entry_spheres,   // #F * 4: centre, radius
    __global const int* node_links,       // #nodes * 2: (right child, 0) or (-1 - first, count)
    __global const real* node_boxes,      // #nodes * 8: box of the node's faces
    __global const real* node_cones,      // #nodes * 4: normal cone (direction, radius)
    const real slack, const real lambda, const int num_points,
    __global real* out) {                  // #T * #P
  const int p = get_global_id(0);
  const int t = get_global_id(1);
  if (p >= num_points) return;
  const real3 q = vload3(p, points) - vload3(t, offsets);
  const real3 n = vload3(p, point_normals);
  real best = INFINITY, reach2 = INFINITY;
  int stack[MAX_STACK];
  real stack_d2[MAX_STACK];
  int sp = 0;
  stack[sp] = 0;
  stack_d2[sp++] = 0;
  while (sp > 0) {
    --sp;
    const int i = stack[sp];
    if (stack_d2[sp] >= reach2) continue;
    const int a = node_links[2 * i];
    if (a < 0) {
      const real df = 1 + lambda * (sqrt(stack_d2[sp]) - slack);
      const real3 dc = n - vload3(0, node_cones + 4 * i);
      const real cone_lb = sqrt(dc.x * dc.x + dc.y * dc.y + dc.z * dc.z) - node_cones[4 * i + 3];
      if (df * (1 + fmax((real)0, cone_lb)) >= best) continue;
      const int j0 = -1 - a, j1 = j0 + node_links[2 * i + 1];
      real r = best / df - 1;
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
          if (lambda > 0) {
            const real reach = (best - 1) / lambda + slack;
            reach2 = reach * reach * (1 + 1e-12);
          }
          r = best / df - 1;
          r2 = r * r * (1 + 1e-12);
        }
      }
      continue;
    }
    // Inner node: push the farther child first so the nearer one is searched first.
    const int left = i + 1, right = a;
    const real dl = box_distance2(q, node_boxes + 8 * left);
    const real dr = box_distance2(q, node_boxes + 8 * right);
    const bool left_first = dl <= dr;
    const int first = left_first ? left : right, second = left_first ? right : left;
    const real d1 = left_first ? dl : dr, d2 = left_first ? dr : dl;
    if (d2 < reach2) {
      stack[sp] = second;
      stack_d2[sp++] = d2;
    }
    if (d1 < reach2) {
      stack[sp] = first;
      stack_d2[sp++] = d1;
    }
  }
  out[t * num_points + p] = best;
}
