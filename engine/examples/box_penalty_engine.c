/* An example engine for the C ABI (gauss6/engine.h): a small, honest penalty
 * renderer with known flaws, to show what an engine exports and what gauss6's
 * oracle makes of it (docs/engine-contract.md, "The example engine").
 *
 * Model: each obstacle is replaced by its world-frame bounding box. The tool is
 * displayed where the handle is (X_WS = X_WH: direct rendering, no proxy). Every
 * tool vertex inside a box is pushed out through the box's nearest face with a
 * spring: f_i = (K / n) d_i n_i (d_i its depth, n_i the face's outward normal, n
 * the number of vertices inside), so the total stiffness is about K however many
 * vertices are in. The wrench is the sum of the f_i and of their torques about G.
 *
 * Known flaws, which the oracle is expected to report: the displayed pose
 * penetrates (a penalty method needs penetration to make force); the box is not
 * the mesh (force at a distance above a hole or a concave surface, penetration
 * of what the box leaves out); the spring under a zero-order hold is not passive.
 *
 * Config text: "stiffness=K" (N/m, default 2000).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gauss6/engine.h"
#include "gauss6/engine_config.h"

typedef struct box {
  double lo[3], hi[3];
} box;

typedef struct engine {
  double stiffness;            /* K, N/m */
  int num_boxes;
  box* boxes;                  /* world frame */
  int num_vertices;
  double* vertices_B;          /* tool vertices, body frame, num_vertices x 3 */
  char error[256];
} engine;

#define GAUSS6_EXPORT __attribute__((visibility("default")))

static void set_error(char* error, size_t size, const char* text) {
  if (error && size) snprintf(error, size, "%s", text);
}

/* R(q) of q / |q|, row-major. */
static void rotation(const double q[4], double R[9]) {
  const double n = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  R[0] = (w * w + x * x - y * y - z * z) / n;
  R[1] = 2 * (x * y - w * z) / n;
  R[2] = 2 * (x * z + w * y) / n;
  R[3] = 2 * (x * y + w * z) / n;
  R[4] = (w * w - x * x + y * y - z * z) / n;
  R[5] = 2 * (y * z - w * x) / n;
  R[6] = 2 * (x * z - w * y) / n;
  R[7] = 2 * (y * z + w * x) / n;
  R[8] = (w * w - x * x - y * y + z * z) / n;
}

static void* create(const char* config, char* error, size_t error_size) {
  engine* e = (engine*)calloc(1, sizeof(engine));
  if (!e) {
    set_error(error, error_size, "box penalty engine: out of memory");
    return NULL;
  }
  e->stiffness = 2000;
  static const char* const keys[] = {"stiffness", NULL};
  if (gauss6_config_check(config, keys, "box penalty engine", error, error_size) != 0) {
    free(e);
    return NULL;
  }
  char value[64], *end = value;
  if (gauss6_config_value(config, "stiffness", value, sizeof value)) {
    e->stiffness = strtod(value, &end);
    if (end == value || *end) e->stiffness = -1;
  }
  if (!(e->stiffness > 0) || !isfinite(e->stiffness)) {
    set_error(error, error_size, "box penalty engine: stiffness must be a positive number");
    free(e);
    return NULL;
  }
  return e;
}

static void release(engine* e) {
  free(e->boxes);
  free(e->vertices_B);
  e->boxes = NULL;
  e->vertices_B = NULL;
}

static int reset(void* handle, const gauss6_scene_desc* s, char* error, size_t error_size) {
  engine* e = (engine*)handle;
  if (s->struct_size < sizeof(gauss6_scene_desc)) {
    set_error(error, error_size, "box penalty engine: scene description too small");
    return GAUSS6_ENGINE_ERROR;
  }
  release(e);
  e->num_boxes = s->num_obstacles;
  e->boxes = (box*)calloc((size_t)(s->num_obstacles > 0 ? s->num_obstacles : 1), sizeof(box));
  e->num_vertices = s->tool.mesh.num_vertices;
  e->vertices_B = (double*)malloc(sizeof(double) * 3 * (size_t)(e->num_vertices > 0 ? e->num_vertices : 1));
  if (!e->boxes || !e->vertices_B) {
    set_error(error, error_size, "box penalty engine: out of memory");
    return GAUSS6_ENGINE_ERROR;
  }
  /* Each obstacle's bounding box, world frame. */
  for (int b = 0; b < s->num_obstacles; ++b) {
    const gauss6_body* body = &s->obstacles[b];
    double R[9];
    rotation(body->X_WB.q, R);
    box* bx = &e->boxes[b];
    for (int c = 0; c < 3; ++c) bx->lo[c] = INFINITY, bx->hi[c] = -INFINITY;
    for (int v = 0; v < body->mesh.num_vertices; ++v) {
      const double* r = &body->mesh.vertices[3 * v];
      for (int c = 0; c < 3; ++c) {
        const double x = body->X_WB.p[c] + R[3 * c] * r[0] + R[3 * c + 1] * r[1] + R[3 * c + 2] * r[2];
        if (x < bx->lo[c]) bx->lo[c] = x;
        if (x > bx->hi[c]) bx->hi[c] = x;
      }
    }
  }
  memcpy(e->vertices_B, s->tool.mesh.vertices, sizeof(double) * 3 * (size_t)e->num_vertices);
  return GAUSS6_ENGINE_OK;
}

static int step(void* handle, double t, const gauss6_pose* X_WH, gauss6_step_out* out) {
  (void)t;
  engine* e = (engine*)handle;
  if (out->struct_size < sizeof(gauss6_step_out)) {
    snprintf(e->error, sizeof e->error, "box penalty engine: step output too small");
    return GAUSS6_ENGINE_ERROR;
  }
  out->X_WS = *X_WH;  /* direct rendering: the tool is where the handle is */
  double R[9];
  rotation(X_WH->q, R);

  /* Pass 1: the vertices inside a box, their depth and push-out normal. */
  double f[3] = {0, 0, 0}, tau[3] = {0, 0, 0};
  int num_inside = 0, written = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (int v = 0; v < e->num_vertices; ++v) {
      const double* r = &e->vertices_B[3 * v];
      double x[3];
      for (int c = 0; c < 3; ++c) x[c] = X_WH->p[c] + R[3 * c] * r[0] + R[3 * c + 1] * r[1] + R[3 * c + 2] * r[2];
      for (int b = 0; b < e->num_boxes; ++b) {
        const box* bx = &e->boxes[b];
        double depth = INFINITY, n[3] = {0, 0, 0};
        int inside = 1;
        for (int c = 0; c < 3 && inside; ++c) {
          const double below = x[c] - bx->lo[c], above = bx->hi[c] - x[c];
          if (below <= 0 || above <= 0) inside = 0;
          else if (below < depth || above < depth) {
            depth = below < above ? below : above;
            n[0] = n[1] = n[2] = 0;
            n[c] = below < above ? -1 : 1;
          }
        }
        if (!inside) continue;
        if (pass == 0) {
          ++num_inside;
          continue;
        }
        /* Pass 2: the spring of this vertex and its torque about G. */
        const double k = e->stiffness / num_inside;
        const double fi[3] = {k * depth * n[0], k * depth * n[1], k * depth * n[2]};
        const double arm[3] = {x[0] - X_WH->p[0], x[1] - X_WH->p[1], x[2] - X_WH->p[2]};
        for (int c = 0; c < 3; ++c) f[c] += fi[c];
        tau[0] += arm[1] * fi[2] - arm[2] * fi[1];
        tau[1] += arm[2] * fi[0] - arm[0] * fi[2];
        tau[2] += arm[0] * fi[1] - arm[1] * fi[0];
        if (written < out->contact_capacity && out->contacts) {
          gauss6_contact* ct = &out->contacts[written++];
          for (int c = 0; c < 3; ++c) ct->point[c] = x[c], ct->normal[c] = n[c];
          ct->separation = -depth;
        }
      }
    }
    if (num_inside == 0) break;
  }
  for (int c = 0; c < 3; ++c) out->wrench[c] = f[c], out->wrench[3 + c] = tau[c];
  out->num_contacts = written;
  out->step_seconds = -1;  /* not measured: the caller times the call */
  return GAUSS6_ENGINE_OK;
}

static const char* last_error(void* handle) { return ((engine*)handle)->error; }

static void destroy(void* handle) {
  if (!handle) return;
  release((engine*)handle);
  free(handle);
}

static const gauss6_engine_v1 kTable = {
    GAUSS6_ENGINE_ABI_VERSION, sizeof(gauss6_engine_v1), sizeof(gauss6_scene_desc), sizeof(gauss6_step_out),
    "box penalty (example, C)", create, reset, step, last_error, destroy,
};

GAUSS6_EXPORT const void* gauss6_engine_get(uint32_t abi_version) {
  return abi_version == GAUSS6_ENGINE_ABI_VERSION ? &kTable : NULL;
}
