/*
 * smtcal_runtime.c - the C99 runtime of smtcal's periphery calibration (see
 * smtcal_runtime.h for the API and docs/periphery.md for the math).
 *
 * Every step mirrors smtcal's C++ implementation in the same order
 * (calibration/fixture_estimation.cpp for the scan, calibration/error_table.cpp and
 * calibration/inverse_calibration.cpp for the tables), so the two agree to
 * rounding; tests/unit/backend/fixture_c_runtime_test.cpp holds them within 1e-9 mm.
 * No heap, no writable globals, fixed arrays, only sqrt and atan2 from libm.
 */
#include "smtcal_runtime.h"

#include <math.h>
#include <stddef.h>

#define SMTCAL_PI 3.14159265358979323846
#define SMTCAL_DEG_PER_RAD 57.29577951308232

/* ------------------------------------------------------------------ helpers */

static double abs_d(double v) { return v < 0 ? -v : v; }
static double max_d(double a, double b) { return a > b ? a : b; }
static double clamp_d(double v, double lo, double hi) { return v < lo ? lo : (v > hi ? hi : v); }
static double cross2(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }
static double hypot2(double x, double y) { return sqrt(x * x + y * y); }

/* Solves the symmetric 2 x 2 system [[m00, m01], [m10, m11]] x = b; 0 when it
 * is singular relative to its size. */
static int solve2(double m00, double m01, double m10, double m11, double b0, double b1, double x[2]) {
  double det = m00 * m11 - m01 * m10;
  double trace = abs_d(m00) + abs_d(m11);
  if (!(abs_d(det) > SMTCAL_MIN_RELATIVE_DETERMINANT * trace * trace)) return 0;
  x[0] = (m11 * b0 - m01 * b1) / det;
  x[1] = (m00 * b1 - m10 * b0) / det;
  return 1;
}

static void fix_to_base(const smtcal_fix *fix, double fx, double fy, double out[2]) {
  out[0] = fix->n[0] * fx + fix->o[0] * fy + fix->p[0];
  out[1] = fix->n[1] * fx + fix->o[1] * fy + fix->p[1];
}

/* The angle of b's x axis relative to a's, wrapped to -pi..pi. */
static double relative_angle(const double na[2], const double nb[2]) {
  return atan2(na[0] * nb[1] - na[1] * nb[0], na[0] * nb[0] + na[1] * nb[1]);
}

/* ------------------------------------------------------------------ tables */

/* The cell i with lines[i] <= v < lines[i + 1] (the last cell includes its
 * end); v within the lines. A guess from the mean pitch, then a binary search
 * when the guess is off by more than one cell. */
static int table_cell(const double *lines, int count, double v) {
  int last_cell = count - 2;
  double cells_per_mm = (double)(count - 1) / (lines[count - 1] - lines[0]);
  double guess = (v - lines[0]) * cells_per_mm;
  int i = guess <= 0 ? 0 : (guess >= last_cell ? last_cell : (int)guess);
  if (i > 0 && v < lines[i]) --i;
  if (i < last_cell && v >= lines[i + 1]) ++i;
  if ((i > 0 && v < lines[i]) || (i < last_cell && v >= lines[i + 1])) {
    int lo = 1, hi = count - 1; /* the first line in [1, count - 1) above v */
    while (lo < hi) {
      int mid = lo + (hi - lo) / 2;
      if (lines[mid] > v) {
        hi = mid;
      } else {
        lo = mid + 1;
      }
    }
    i = lo - 1;
  }
  return i;
}

/* Bilinear value of one axis table at (x, y) inside its grid, and its
 * gradient when ddx is not NULL. */
static double table_evaluate(const smtcal_axis_table *t, double x, double y, double *ddx, double *ddy) {
  int i = table_cell(t->xs, t->nx, x);
  int j = table_cell(t->ys, t->ny, y);
  double x0 = t->xs[i], hx = t->xs[i + 1] - x0;
  double y0 = t->ys[j], hy = t->ys[j + 1] - y0;
  double s = (x - x0) / hx;
  double u = (y - y0) / hy;
  const double *row0 = &t->values[j * t->nx + i];
  const double *row1 = row0 + t->nx;
  double v00 = row0[0], v10 = row0[1], v01 = row1[0], v11 = row1[1];
  double bottom = (1 - s) * v00 + s * v10;
  double top = (1 - s) * v01 + s * v11;
  if (ddx != NULL) {
    *ddx = ((1 - u) * (v10 - v00) + u * (v11 - v01)) / hx;
    *ddy = (top - bottom) / hy;
  }
  return (1 - u) * bottom + u * top;
}

static int region_inside(const smtcal_region *r, double x, double y) {
  return x >= r->domain_x0 - SMTCAL_TABLE_EDGE_TOL_MM && x <= r->domain_x1 + SMTCAL_TABLE_EDGE_TOL_MM &&
         y >= r->domain_y0 - SMTCAL_TABLE_EDGE_TOL_MM && y <= r->domain_y1 + SMTCAL_TABLE_EDGE_TOL_MM;
}

/* Delta at n clamped into the domain, and its Jacobian (zero along a clamped
 * coordinate) when jacobian is not NULL. */
static void region_delta(const smtcal_region *r, const double n[2], double delta[2], double jacobian[4]) {
  double px = clamp_d(n[0], r->domain_x0, r->domain_x1);
  double py = clamp_d(n[1], r->domain_y0, r->domain_y1);
  if (jacobian == NULL) {
    delta[0] = table_evaluate(&r->dx, px, py, NULL, NULL);
    delta[1] = table_evaluate(&r->dy, px, py, NULL, NULL);
    return;
  }
  delta[0] = table_evaluate(&r->dx, px, py, &jacobian[0], &jacobian[1]);
  delta[1] = table_evaluate(&r->dy, px, py, &jacobian[2], &jacobian[3]);
  if (px != n[0]) jacobian[0] = jacobian[2] = 0;
  if (py != n[1]) jacobian[1] = jacobian[3] = 0;
}

static double inf_norm(const double v[2]) { return max_d(abs_d(v[0]), abs_d(v[1])); }

/* The default inverse solver of calibration/inverse_calibration.cpp: Newton on
 * F(n) - a, a step kept only when it shrinks the residual at least as much
 * as the contracting fixed-point step n <- a - Delta(n), which is taken
 * otherwise; at most iteration_bound iterations. */
static smtcal_point_status region_solve(const smtcal_region *r, const double actual[2], smtcal_corrected *out) {
  double n[2], delta[2], jac[4], residual[2], norm;
  int iterations = 0;
  smtcal_point_status status = SMTCAL_POINT_OK;
  n[0] = actual[0];
  n[1] = actual[1];
  region_delta(r, n, delta, jac);
  residual[0] = n[0] + delta[0] - actual[0];
  residual[1] = n[1] + delta[1] - actual[1];
  norm = hypot2(residual[0], residual[1]);
  while (norm > SMTCAL_INVERSE_POLISH_MM && iterations < r->iteration_bound) {
    double previous_n[2], previous_delta[2], previous_residual[2], previous_jac[4];
    double a, b, c, d, det, new_norm;
    int accepted = 0, k;
    ++iterations;
    for (k = 0; k < 2; ++k) {
      previous_n[k] = n[k];
      previous_delta[k] = delta[k];
      previous_residual[k] = residual[k];
    }
    for (k = 0; k < 4; ++k) previous_jac[k] = jac[k];
    a = 1 + jac[0];
    b = jac[1];
    c = jac[2];
    d = 1 + jac[3];
    det = a * d - b * c;
    if (det > 0) {
      double trial[2], trial_delta[2], trial_jac[4], trial_residual[2];
      trial[0] = n[0] - (d * residual[0] - b * residual[1]) / det;
      trial[1] = n[1] - (a * residual[1] - c * residual[0]) / det;
      region_delta(r, trial, trial_delta, trial_jac);
      trial_residual[0] = trial[0] + trial_delta[0] - actual[0];
      trial_residual[1] = trial[1] + trial_delta[1] - actual[1];
      if (inf_norm(trial_residual) <= r->contraction * inf_norm(residual)) {
        for (k = 0; k < 2; ++k) {
          n[k] = trial[k];
          delta[k] = trial_delta[k];
          residual[k] = trial_residual[k];
        }
        for (k = 0; k < 4; ++k) jac[k] = trial_jac[k];
        accepted = 1;
      }
    }
    if (!accepted) {
      n[0] = actual[0] - delta[0];
      n[1] = actual[1] - delta[1];
      region_delta(r, n, delta, jac);
      residual[0] = n[0] + delta[0] - actual[0];
      residual[1] = n[1] + delta[1] - actual[1];
    }
    new_norm = hypot2(residual[0], residual[1]);
    if (!(new_norm < norm)) { /* rounding: keep the better point */
      for (k = 0; k < 2; ++k) {
        n[k] = previous_n[k];
        delta[k] = previous_delta[k];
        residual[k] = previous_residual[k];
      }
      for (k = 0; k < 4; ++k) jac[k] = previous_jac[k];
      break;
    }
    norm = new_norm;
  }
  if (norm > SMTCAL_INVERSE_RESIDUAL_TOL_MM) status = SMTCAL_POINT_NOT_CONVERGED;
  out->command[0] = n[0];
  out->command[1] = n[1];
  out->residual = norm;
  out->iterations = iterations;
  /* The outside policy, on the solved nominal position. */
  if (!region_inside(r, n[0], n[1])) {
    switch (r->outside) {
      case SMTCAL_OUTSIDE_ERROR:
        status = SMTCAL_POINT_OUTSIDE;
        break;
      case SMTCAL_OUTSIDE_CLAMP:
        if (status != SMTCAL_POINT_NOT_CONVERGED) status = SMTCAL_POINT_CLAMPED;
        break;
      case SMTCAL_OUTSIDE_NONE:
        out->command[0] = actual[0];
        out->command[1] = actual[1];
        out->residual = 0;
        out->iterations = 0;
        status = SMTCAL_POINT_UNCORRECTED;
        break;
    }
  }
  out->status = status;
  return status;
}

smtcal_point_status smtcal_direct(const smtcal_region *region, const double nominal[2], double actual[2]) {
  double delta[2];
  if (region == NULL || nominal == NULL || actual == NULL) return SMTCAL_POINT_BAD_ARGUMENT;
  region_delta(region, nominal, delta, NULL);
  actual[0] = nominal[0] + delta[0];
  actual[1] = nominal[1] + delta[1];
  return region_inside(region, nominal[0], nominal[1]) ? SMTCAL_POINT_OK : SMTCAL_POINT_CLAMPED;
}

smtcal_point_status smtcal_invert(const smtcal_region *regions, int region_count, const double required[2],
                                  smtcal_corrected *out) {
  int r;
  if (out == NULL || required == NULL || (regions == NULL && region_count > 0)) return SMTCAL_POINT_BAD_ARGUMENT;
  out->required[0] = required[0];
  out->required[1] = required[1];
  out->residual = 0;
  out->iterations = 0;
  for (r = 0; r < region_count; ++r) {
    const smtcal_region *region = &regions[r];
    if (required[0] >= region->x_lo && required[0] <= region->x_hi && required[1] >= region->y_lo &&
        required[1] <= region->y_hi) {
      out->region = r;
      return region_solve(region, required, out);
    }
  }
  out->region = -1;
  out->command[0] = required[0];
  out->command[1] = required[1];
  out->status = SMTCAL_POINT_NO_REGION;
  return out->status;
}

smtcal_point_status smtcal_correct(const smtcal_fix *fix, const smtcal_region *regions, int region_count,
                                   const double point[2], smtcal_corrected *out) {
  double required[2];
  if (fix == NULL || point == NULL || out == NULL) return SMTCAL_POINT_BAD_ARGUMENT;
  fix_to_base(fix, point[0], point[1], required);
  out->z = 0;
  out->u_deg = 0;
  return smtcal_invert(regions, region_count, required, out);
}

double smtcal_fix_angle_deg(const smtcal_fix *fix) { return atan2(fix->n[1], fix->n[0]) * SMTCAL_DEG_PER_RAD; }

smtcal_point_status smtcal_program_point(const smtcal_program *program, const smtcal_fix *fix, int index,
                                         smtcal_corrected *out) {
  const smtcal_point *point;
  double xy[2];
  smtcal_point_status status;
  if (program == NULL || out == NULL || index < 0 || index >= program->point_count) return SMTCAL_POINT_BAD_ARGUMENT;
  point = &program->points[index];
  xy[0] = point->x;
  xy[1] = point->y;
  if (point->fixture < 0) {
    status = smtcal_invert(program->regions, program->region_count, xy, out);
    out->u_deg = point->u_deg;
  } else {
    if (fix == NULL) return SMTCAL_POINT_BAD_ARGUMENT;
    status = smtcal_correct(fix, program->regions, program->region_count, xy, out);
    out->u_deg = point->u_deg + smtcal_fix_angle_deg(fix);
  }
  out->z = point->z;
  return status;
}

/* ------------------------------------------------------------------ estimators */

/* A fitted line: a point on it and a unit direction. */
typedef struct line2 {
  double px, py, dx, dy;
} line2;

/* The total-least-squares line of the trips on `edge`; 0 when they are closer
 * together than SMTCAL_MIN_TRIP_SEPARATION_MM (no direction). */
static int fit_line(const smtcal_fixture *fx, const double trips[][2], int edge, line2 *line) {
  int k, m, count = 0;
  double spread = 0, cx = 0, cy = 0, sxx = 0, sxy = 0, syy = 0, half, lambda, ax, ay, bx, by, norm;
  for (k = 0; k < fx->trip_count; ++k) {
    if (fx->trip_edge[k] != edge) continue;
    ++count;
    for (m = k + 1; m < fx->trip_count; ++m) {
      if (fx->trip_edge[m] != edge) continue;
      spread = max_d(spread, hypot2(trips[k][0] - trips[m][0], trips[k][1] - trips[m][1]));
    }
  }
  if (count < 2 || !(spread >= SMTCAL_MIN_TRIP_SEPARATION_MM)) return 0;
  for (k = 0; k < fx->trip_count; ++k) {
    if (fx->trip_edge[k] != edge) continue;
    cx += trips[k][0];
    cy += trips[k][1];
  }
  cx /= count;
  cy /= count;
  for (k = 0; k < fx->trip_count; ++k) {
    double ddx, ddy;
    if (fx->trip_edge[k] != edge) continue;
    ddx = trips[k][0] - cx;
    ddy = trips[k][1] - cy;
    sxx += ddx * ddx;
    sxy += ddx * ddy;
    syy += ddy * ddy;
  }
  half = 0.5 * (sxx - syy);
  lambda = 0.5 * (sxx + syy) + sqrt(half * half + sxy * sxy);
  ax = sxy;
  ay = lambda - sxx;
  bx = lambda - syy;
  by = sxy;
  if (ax * ax + ay * ay >= bx * bx + by * by) {
    line->dx = ax;
    line->dy = ay;
  } else {
    line->dx = bx;
    line->dy = by;
  }
  norm = hypot2(line->dx, line->dy);
  line->dx /= norm;
  line->dy /= norm;
  line->px = cx;
  line->py = cy;
  return 1;
}

static int intersect(const line2 *a, const line2 *b, double out[2]) {
  double sine = cross2(a->dx, a->dy, b->dx, b->dy), t;
  if (!(abs_d(sine) >= SMTCAL_MIN_LINE_CROSSING_SIN)) return 0;
  t = cross2(b->px - a->px, b->py - a->py, b->dx, b->dy) / sine;
  out[0] = a->px + t * a->dx;
  out[1] = a->py + t * a->dy;
  return 1;
}

/* Eq. 4 on the crossings S1 = p1 x p2, S2 = p1 x p3, S3 = p2 x p4. */
static int paper_fix(const smtcal_fixture *fx, const double trips[][2], smtcal_fix *fix) {
  line2 lines[SMTCAL_EDGE_COUNT];
  double s1[2], s2[2], s3[2];
  int e;
  for (e = 0; e < SMTCAL_EDGE_COUNT; ++e) {
    if (!fit_line(fx, trips, e, &lines[e])) return 0;
  }
  if (!intersect(&lines[0], &lines[1], s1) || !intersect(&lines[0], &lines[2], s2) ||
      !intersect(&lines[1], &lines[3], s3)) {
    return 0;
  }
  fix->n[0] = (s2[0] - s1[0]) / fx->l1;
  fix->n[1] = (s2[1] - s1[1]) / fx->l1;
  fix->o[0] = (s3[0] - s1[0]) / fx->l2;
  fix->o[1] = (s3[1] - s1[1]) / fx->l2;
  fix->p[0] = s1[0];
  fix->p[1] = s1[1];
  return 1;
}

/* The rigid and rigid-scale least squares (derivation in
 * calibration/fixture_estimation.cpp and docs/periphery.md): in the nominal
 * fixture frame, eliminate the translation, solve Q u = g for
 * u = (cos, sin) / scale, and for rigid move u along the unit circle by
 * Newton steps. */
static int rigid_fix(const smtcal_fixture *fx, const double trips[][2], int with_scale, smtcal_fix *fix) {
  double a[SMTCAL_MAX_TRIPS], b[SMTCAL_MAX_TRIPS], nx[SMTCAL_MAX_TRIPS], ny[SMTCAL_MAX_TRIPS];
  double d[SMTCAL_MAX_TRIPS], pa[SMTCAL_MAX_TRIPS], pb[SMTCAL_MAX_TRIPS], pd[SMTCAL_MAX_TRIPS];
  double n00 = 0, n01 = 0, n11 = 0, w[2], q00 = 0, q01 = 0, q11 = 0, g0 = 0, g1 = 0, u[2], scale, norm;
  double t0, t1, ab[2], pdx, pdy, rc, rs;
  int k, i, count = fx->trip_count;
  for (k = 0; k < count; ++k) {
    int e = fx->trip_edge[k];
    double rx = trips[k][0] - fx->origin_x, ry = trips[k][1] - fx->origin_y;
    double qx = fx->cos_angle * rx + fx->sin_angle * ry; /* R_nominal^T (t - p_nominal) */
    double qy = -fx->sin_angle * rx + fx->cos_angle * ry;
    nx[k] = fx->edge_normal[e][0];
    ny[k] = fx->edge_normal[e][1];
    d[k] = fx->edge_offset[e];
    a[k] = nx[k] * qx + ny[k] * qy;
    b[k] = cross2(nx[k], ny[k], qx, qy);
    n00 += nx[k] * nx[k];
    n01 += nx[k] * ny[k];
    n11 += ny[k] * ny[k];
  }
  /* P v = v - N (N^T N)^-1 N^T v for v = A, B, d. */
  {
    const double *columns[3];
    double *projected[3];
    int c;
    columns[0] = a;
    columns[1] = b;
    columns[2] = d;
    projected[0] = pa;
    projected[1] = pb;
    projected[2] = pd;
    for (c = 0; c < 3; ++c) {
      double v0 = 0, v1 = 0;
      for (k = 0; k < count; ++k) {
        v0 += nx[k] * columns[c][k];
        v1 += ny[k] * columns[c][k];
      }
      if (!solve2(n00, n01, n01, n11, v0, v1, w)) return 0;
      for (k = 0; k < count; ++k) projected[c][k] = columns[c][k] - (nx[k] * w[0] + ny[k] * w[1]);
    }
  }
  for (k = 0; k < count; ++k) {
    q00 += pa[k] * pa[k];
    q01 += pa[k] * pb[k];
    q11 += pb[k] * pb[k];
    g0 += pa[k] * pd[k];
    g1 += pb[k] * pd[k];
  }
  if (!solve2(q00, q01, q01, q11, g0, g1, u)) return 0;
  norm = hypot2(u[0], u[1]);
  if (!(norm > 0)) return 0;
  scale = 1 / norm;
  u[0] *= scale;
  u[1] *= scale;
  if (!with_scale) {
    scale = 1;
    for (i = 0; i < SMTCAL_RIGID_MAX_ITERATIONS; ++i) {
      double qu0, qu1, slope, curvature, step;
      t0 = -u[1];
      t1 = u[0];
      qu0 = q00 * u[0] + q01 * u[1];
      qu1 = q01 * u[0] + q11 * u[1];
      slope = 2 * (t0 * (qu0 - g0) + t1 * (qu1 - g1));
      curvature = 2 * ((t0 * (q00 * t0 + q01 * t1) + t1 * (q01 * t0 + q11 * t1)) - (u[0] * qu0 + u[1] * qu1) +
                       (g0 * u[0] + g1 * u[1]));
      if (!(curvature > 0)) break;
      step = -slope / curvature;
      u[0] += step * t0;
      u[1] += step * t1;
      norm = hypot2(u[0], u[1]);
      u[0] /= norm;
      u[1] /= norm;
      if (abs_d(step) <= SMTCAL_RIGID_STEP_TOL_RAD) break;
    }
  }
  /* The translation for this rotation. */
  {
    double v0 = 0, v1 = 0;
    for (k = 0; k < count; ++k) {
      double rhs = u[0] * a[k] + u[1] * b[k] - scale * d[k];
      v0 += nx[k] * rhs;
      v1 += ny[k] * rhs;
    }
    if (!solve2(n00, n01, n01, n11, v0, v1, ab)) return 0;
  }
  pdx = u[0] * ab[0] - u[1] * ab[1];
  pdy = u[1] * ab[0] + u[0] * ab[1];
  rc = scale * u[0];
  rs = scale * u[1];
  /* FIX = R_nominal . (scale R) and p_nominal + R_nominal p_delta. */
  fix->n[0] = fx->cos_angle * rc - fx->sin_angle * rs;
  fix->n[1] = fx->sin_angle * rc + fx->cos_angle * rs;
  fix->o[0] = fx->cos_angle * -rs - fx->sin_angle * rc;
  fix->o[1] = fx->sin_angle * -rs + fx->cos_angle * rc;
  fix->p[0] = fx->origin_x + (fx->cos_angle * pdx - fx->sin_angle * pdy);
  fix->p[1] = fx->origin_y + (fx->sin_angle * pdx + fx->cos_angle * pdy);
  return 1;
}

/* ------------------------------------------------------------------ the scan */

static void set_check(smtcal_scan_result *result, smtcal_scan_status check, double value, double limit, int trip) {
  result->evaluated[check] = 1;
  result->value[check] = value;
  if (!(value <= limit) && result->status == SMTCAL_SCAN_OK) {
    result->status = check;
    result->trip = trip;
  }
}

static void clear_result(smtcal_scan_result *result) {
  int k;
  result->status = SMTCAL_SCAN_OK;
  result->trip = -1;
  result->has_fix = 0;
  result->has_delta = 0;
  result->scale = 0;
  for (k = 0; k < 2; ++k) {
    result->fix.n[k] = result->fix.o[k] = result->fix.p[k] = 0;
    result->delta.n[k] = result->delta.o[k] = result->delta.p[k] = 0;
    result->s[0][k] = result->s[1][k] = result->s[2][k] = 0;
  }
  for (k = 0; k <= SMTCAL_CHECK_COUNT; ++k) {
    result->evaluated[k] = 0;
    result->value[k] = 0;
  }
  for (k = 0; k < SMTCAL_MAX_TRIPS; ++k) {
    result->calibrated[k][0] = result->calibrated[k][1] = 0;
    result->residual[k] = 0;
  }
}

smtcal_scan_status smtcal_scan(const smtcal_fixture *fixture, const smtcal_region *regions, int region_count,
                               const double *trips_xy, const unsigned char *tripped, const smtcal_fix *previous,
                               smtcal_scan_result *result) {
  const smtcal_fixture *fx = fixture;
  smtcal_fix fix;
  double det, inv00, inv01, inv10, inv11, worst_value = 0, angle, sx, sy, ox, oy;
  int k, r, missing = 0, first_missing = -1, worst = -1, ok;
  if (result == NULL) return SMTCAL_SCAN_BAD_ARGUMENT;
  clear_result(result);
  if (fx == NULL || trips_xy == NULL || (regions == NULL && region_count > 0) || fx->trip_count < 1 ||
      fx->trip_count > SMTCAL_MAX_TRIPS) {
    result->status = SMTCAL_SCAN_BAD_ARGUMENT;
    return result->status;
  }

  /* Every trip present, each in its window. */
  for (k = 0; k < fx->trip_count; ++k) {
    if (tripped != NULL && !tripped[k]) {
      if (missing++ == 0) first_missing = k;
    }
  }
  set_check(result, SMTCAL_SCAN_MISSING_TRIP, missing, 0, first_missing);
  if (result->status != SMTCAL_SCAN_OK) return result->status;
  for (k = 0; k < fx->trip_count; ++k) {
    double distance = hypot2(trips_xy[2 * k] - fx->trip_nominal[k][0], trips_xy[2 * k + 1] - fx->trip_nominal[k][1]);
    if (worst < 0 || distance > worst_value) {
      worst = k;
      worst_value = distance;
    }
  }
  set_check(result, SMTCAL_SCAN_TRIP_WINDOW, worst_value, fx->trip_window, worst);
  if (result->status != SMTCAL_SCAN_OK) return result->status;

  /* Where the sensor really was: through the first table that covers it. */
  for (k = 0; k < fx->trip_count; ++k) {
    double t[2];
    t[0] = trips_xy[2 * k];
    t[1] = trips_xy[2 * k + 1];
    result->calibrated[k][0] = t[0];
    result->calibrated[k][1] = t[1];
    for (r = 0; r < region_count; ++r) {
      if (region_inside(&regions[r], t[0], t[1])) {
        smtcal_direct(&regions[r], t, result->calibrated[k]);
        break;
      }
    }
  }

  /* The estimator. */
  ok = fx->estimator == SMTCAL_ESTIMATOR_PAPER
           ? paper_fix(fx, (const double(*)[2])result->calibrated, &fix)
           : rigid_fix(fx, (const double(*)[2])result->calibrated, fx->estimator == SMTCAL_ESTIMATOR_RIGID_SCALE,
                       &fix);
  if (ok) {
    double frobenius = fix.n[0] * fix.n[0] + fix.n[1] * fix.n[1] + fix.o[0] * fix.o[0] + fix.o[1] * fix.o[1];
    det = fix.n[0] * fix.o[1] - fix.o[0] * fix.n[1];
    ok = abs_d(det) > SMTCAL_MIN_RELATIVE_DETERMINANT * frobenius;
  }
  set_check(result, SMTCAL_SCAN_DEGENERATE, ok ? 0 : 1, 0, -1);
  if (!ok) return result->status;

  /* The estimate's checks. */
  fix_to_base(&fix, 0, 0, result->s[0]);
  fix_to_base(&fix, fx->l1, 0, result->s[1]);
  fix_to_base(&fix, 0, fx->l2, result->s[2]);
  result->scale = hypot2(fix.n[0], fix.n[1]);
  sx = result->s[1][0] - result->s[0][0];
  sy = result->s[1][1] - result->s[0][1];
  ox = result->s[2][0] - result->s[0][0];
  oy = result->s[2][1] - result->s[0][1];
  set_check(result, SMTCAL_SCAN_LENGTH_L1, abs_d(hypot2(sx, sy) - fx->l1), fx->length_tolerance, -1);
  set_check(result, SMTCAL_SCAN_LENGTH_L2, abs_d(hypot2(ox, oy) - fx->l2), fx->length_tolerance, -1);
  angle = atan2(cross2(sx, sy, ox, oy), sx * ox + sy * oy);
  set_check(result, SMTCAL_SCAN_SQUARENESS, abs_d(angle - SMTCAL_PI / 2) * SMTCAL_DEG_PER_RAD, fx->squareness_deg,
            -1);
  /* Residuals: a trip's distance from its edge line n . f = d as FIX places
   * it, |n . A^-1 (t - p) - d| / |A^-T n|. */
  inv00 = fix.o[1] / det;
  inv01 = -fix.o[0] / det;
  inv10 = -fix.n[1] / det;
  inv11 = fix.n[0] / det;
  worst = -1;
  worst_value = 0;
  for (k = 0; k < fx->trip_count; ++k) {
    int e = fx->trip_edge[k];
    double enx = fx->edge_normal[e][0], eny = fx->edge_normal[e][1];
    double mx = inv00 * enx + inv10 * eny, my = inv01 * enx + inv11 * eny;
    double rx = result->calibrated[k][0] - fix.p[0], ry = result->calibrated[k][1] - fix.p[1];
    double fxx = inv00 * rx + inv01 * ry, fyy = inv10 * rx + inv11 * ry;
    result->residual[k] = abs_d(enx * fxx + eny * fyy - fx->edge_offset[e]) / hypot2(mx, my);
    if (worst < 0 || result->residual[k] > worst_value) {
      worst = k;
      worst_value = result->residual[k];
    }
  }
  set_check(result, SMTCAL_SCAN_LINE_RESIDUAL, worst_value, fx->max_line_residual, worst);
  {
    double nominal_n[2];
    nominal_n[0] = fx->cos_angle;
    nominal_n[1] = fx->sin_angle;
    set_check(result, SMTCAL_SCAN_NOMINAL_SHIFT, hypot2(fix.p[0] - fx->origin_x, fix.p[1] - fx->origin_y),
              fx->max_shift, -1);
    set_check(result, SMTCAL_SCAN_NOMINAL_ROTATION, abs_d(relative_angle(nominal_n, fix.n)) * SMTCAL_DEG_PER_RAD,
              fx->max_rotation_deg, -1);
  }
  if (previous != NULL) {
    /* delta = FIX . previous^-1 */
    double pdet = previous->n[0] * previous->o[1] - previous->o[0] * previous->n[1];
    double p00 = previous->o[1] / pdet, p01 = -previous->o[0] / pdet;
    double p10 = -previous->n[1] / pdet, p11 = previous->n[0] / pdet;
    double tx = -(p00 * previous->p[0] + p01 * previous->p[1]), ty = -(p10 * previous->p[0] + p11 * previous->p[1]);
    result->delta.n[0] = fix.n[0] * p00 + fix.o[0] * p10;
    result->delta.n[1] = fix.n[1] * p00 + fix.o[1] * p10;
    result->delta.o[0] = fix.n[0] * p01 + fix.o[0] * p11;
    result->delta.o[1] = fix.n[1] * p01 + fix.o[1] * p11;
    result->delta.p[0] = fix.n[0] * tx + fix.o[0] * ty + fix.p[0];
    result->delta.p[1] = fix.n[1] * tx + fix.o[1] * ty + fix.p[1];
    result->has_delta = 1;
    set_check(result, SMTCAL_SCAN_CYCLE_SHIFT, hypot2(fix.p[0] - previous->p[0], fix.p[1] - previous->p[1]),
              fx->max_shift, -1);
    set_check(result, SMTCAL_SCAN_CYCLE_ROTATION, abs_d(relative_angle(previous->n, fix.n)) * SMTCAL_DEG_PER_RAD,
              fx->max_rotation_deg, -1);
  }
  if (result->status == SMTCAL_SCAN_OK) {
    result->fix = fix;
    result->has_fix = 1;
  }
  return result->status;
}

/* ------------------------------------------------------------------ data checks */

static int lines_ok(const double *lines, int count) {
  int i;
  if (lines == NULL || count < 2) return 0;
  for (i = 0; i + 1 < count; ++i) {
    if (!(lines[i + 1] > lines[i])) return 0;
  }
  return 1;
}

static int axis_ok(const smtcal_axis_table *t) {
  int i;
  if (!lines_ok(t->xs, t->nx) || !lines_ok(t->ys, t->ny) || t->values == NULL) return 0;
  for (i = 0; i < t->nx * t->ny; ++i) {
    if (!(t->values[i] == t->values[i])) return 0; /* NaN */
  }
  return 1;
}

smtcal_data_status smtcal_check_region(const smtcal_region *region) {
  const smtcal_region *r = region;
  if (r == NULL) return SMTCAL_DATA_NULL;
  if (!axis_ok(&r->dx) || !axis_ok(&r->dy)) return SMTCAL_DATA_TABLE;
  /* The domain is where both grids overlap. */
  if (r->domain_x0 != max_d(r->dx.xs[0], r->dy.xs[0]) || r->domain_y0 != max_d(r->dx.ys[0], r->dy.ys[0]) ||
      r->domain_x1 != -max_d(-r->dx.xs[r->dx.nx - 1], -r->dy.xs[r->dy.nx - 1]) ||
      r->domain_y1 != -max_d(-r->dx.ys[r->dx.ny - 1], -r->dy.ys[r->dy.ny - 1]) || !(r->domain_x1 > r->domain_x0) ||
      !(r->domain_y1 > r->domain_y0)) {
    return SMTCAL_DATA_TABLE;
  }
  if (!(r->contraction >= 0 && r->contraction < 1) || r->iteration_bound < 0 ||
      (r->outside != SMTCAL_OUTSIDE_ERROR && r->outside != SMTCAL_OUTSIDE_CLAMP && r->outside != SMTCAL_OUTSIDE_NONE)) {
    return SMTCAL_DATA_TABLE;
  }
  return SMTCAL_DATA_OK;
}

smtcal_data_status smtcal_check_fixture(const smtcal_fixture *fixture) {
  const smtcal_fixture *fx = fixture;
  int k, e;
  if (fx == NULL) return SMTCAL_DATA_NULL;
  if (fx->trip_count < 1 || fx->trip_count > SMTCAL_MAX_TRIPS || !(fx->l1 > 0) || !(fx->l2 > 0)) {
    return SMTCAL_DATA_FIXTURE;
  }
  if (fx->estimator != SMTCAL_ESTIMATOR_PAPER && fx->estimator != SMTCAL_ESTIMATOR_RIGID &&
      fx->estimator != SMTCAL_ESTIMATOR_RIGID_SCALE) {
    return SMTCAL_DATA_FIXTURE;
  }
  if (abs_d(fx->cos_angle * fx->cos_angle + fx->sin_angle * fx->sin_angle - 1) > 1e-12) return SMTCAL_DATA_FIXTURE;
  for (e = 0; e < SMTCAL_EDGE_COUNT; ++e) {
    double norm = hypot2(fx->edge_normal[e][0], fx->edge_normal[e][1]);
    if (abs_d(norm - 1) > 1e-12) return SMTCAL_DATA_FIXTURE;
  }
  for (k = 0; k < fx->trip_count; ++k) {
    if (fx->trip_edge[k] < 0 || fx->trip_edge[k] >= SMTCAL_EDGE_COUNT) return SMTCAL_DATA_FIXTURE;
  }
  if (!(fx->trip_window >= 0 && fx->max_shift >= 0 && fx->max_rotation_deg >= 0 && fx->length_tolerance >= 0 &&
        fx->squareness_deg >= 0 && fx->max_line_residual >= 0)) {
    return SMTCAL_DATA_FIXTURE;
  }
  return SMTCAL_DATA_OK;
}

smtcal_data_status smtcal_check_program(const smtcal_program *program) {
  int i;
  smtcal_data_status status;
  if (program == NULL || (program->regions == NULL && program->region_count > 0) ||
      (program->fixtures == NULL && program->fixture_count > 0) ||
      (program->points == NULL && program->point_count > 0)) {
    return SMTCAL_DATA_NULL;
  }
  for (i = 0; i < program->region_count; ++i) {
    status = smtcal_check_region(&program->regions[i]);
    if (status != SMTCAL_DATA_OK) return status;
  }
  for (i = 0; i < program->fixture_count; ++i) {
    status = smtcal_check_fixture(&program->fixtures[i]);
    if (status != SMTCAL_DATA_OK) return status;
  }
  for (i = 0; i < program->point_count; ++i) {
    if (program->points[i].fixture < -1 || program->points[i].fixture >= program->fixture_count) {
      return SMTCAL_DATA_POINT;
    }
  }
  return SMTCAL_DATA_OK;
}

/* ------------------------------------------------------------------ names */

const char *smtcal_scan_status_name(smtcal_scan_status status) {
  switch (status) {
    case SMTCAL_SCAN_OK: return "ok";
    case SMTCAL_SCAN_MISSING_TRIP: return "missing_trip";
    case SMTCAL_SCAN_TRIP_WINDOW: return "trip_window";
    case SMTCAL_SCAN_DEGENERATE: return "degenerate";
    case SMTCAL_SCAN_LENGTH_L1: return "length_l1";
    case SMTCAL_SCAN_LENGTH_L2: return "length_l2";
    case SMTCAL_SCAN_SQUARENESS: return "squareness";
    case SMTCAL_SCAN_LINE_RESIDUAL: return "line_residual";
    case SMTCAL_SCAN_NOMINAL_SHIFT: return "nominal_shift";
    case SMTCAL_SCAN_NOMINAL_ROTATION: return "nominal_rotation";
    case SMTCAL_SCAN_CYCLE_SHIFT: return "cycle_shift";
    case SMTCAL_SCAN_CYCLE_ROTATION: return "cycle_rotation";
    case SMTCAL_SCAN_BAD_ARGUMENT: return "bad_argument";
  }
  return "unknown";
}

const char *smtcal_point_status_name(smtcal_point_status status) {
  switch (status) {
    case SMTCAL_POINT_OK: return "ok";
    case SMTCAL_POINT_CLAMPED: return "clamped";
    case SMTCAL_POINT_UNCORRECTED: return "uncorrected";
    case SMTCAL_POINT_OUTSIDE: return "outside";
    case SMTCAL_POINT_NOT_CONVERGED: return "not-converged";
    case SMTCAL_POINT_NO_REGION: return "no-region";
    case SMTCAL_POINT_BAD_ARGUMENT: return "bad_argument";
  }
  return "unknown";
}
