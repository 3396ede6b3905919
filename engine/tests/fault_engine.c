/* A test engine with switchable planted faults, for the oracle's own tests
 * (python/tests/test_validate.py): it loads an inner engine through the C ABI
 * (gauss6/engine.h; in the tests, gauss6's own, which passes every check) and
 * passes its steps through, but for one planted fault, so that each fault alone
 * must be caught and named by the oracle's right check (docs/engine-contract.md).
 *
 * Config text, ';'-separated: "inner=PATH;fault=NAME;at=T[;jump=X,Y,Z]".
 * Faults (each acts at the first tick t >= at that meets its condition, once
 * unless said otherwise):
 *   none         the inner engine's steps unchanged
 *   penetrate    a tick with contacts: the pose moved 1e-4 (+ the contact's
 *                separation) along -n of its first contact: 1e-4 inside the obstacle
 *   tangential   every tick with contacts and force from then on: 5% of |f|
 *                added to the force along a unit tangent of the first contact
 *   distance     a tick with contacts and force: the pose moved 10 delta along
 *                +n, the wrench kept: a force at about 10 delta of separation
 *   energy       at each new contact (contacts after a tick without) from then
 *                on, once the contact carries 1 N, for 40 ticks while the inner
 *                engine has contacts and force:
 *                an extra wrench c J_k^T along the first contact (a push out of
 *                the obstacle, in the contact cone), c rising 0.1 N a tick to 2 N
 *                and back, never above the inner force |f| (so that it dies out
 *                with the contact): no tick jumps by more than about 0.1 N
 *   nan          one tick: the force's x component is NaN
 *   tunnel       a tick without contacts: the pose moved by `jump` (default
 *                0, 0, -0.18: from above the peg scene's box to below it), so
 *                that the motion from the last pose and back to the next passes
 *                through the obstacle while both ends are free
 */
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gauss6/engine.h"
#include "gauss6/engine_config.h"

enum fault { kNone, kPenetrate, kTangential, kDistance, kEnergy, kNan, kTunnel };

typedef struct engine {
  void* library;
  const gauss6_engine_v1* inner;
  void* inner_engine;
  enum fault fault;
  double at;
  double jump[3];
  double delta;
  int done;                   /* a once-only fault has acted */
  int had_contacts;           /* last tick had contacts (energy) */
  int kick_tick;              /* ticks since the last new contact (energy); -1: none */
  char error[512];
} engine;

#define GAUSS6_EXPORT __attribute__((visibility("default")))

static void set_error(char* error, size_t size, const char* text) {
  if (error && size) snprintf(error, size, "%s", text);
}

static void* create(const char* config, char* error, size_t error_size) {
  char path[1024] = "", name[64] = "none", value[128];
  static const char* const keys[] = {"inner", "fault", "at", "jump", NULL};
  if (gauss6_config_check(config, keys, "fault engine", error, error_size) != 0) return NULL;
  if (!gauss6_config_value(config, "inner", path, sizeof path)) {
    set_error(error, error_size, "fault engine: config needs inner=PATH");
    return NULL;
  }
  gauss6_config_value(config, "fault", name, sizeof name);
  engine* e = (engine*)calloc(1, sizeof(engine));
  if (!e) return NULL;
  static const char* const names[] = {"none", "penetrate", "tangential", "distance", "energy", "nan", "tunnel"};
  e->fault = (enum fault)-1;
  for (int i = 0; i < 7; ++i)
    if (strcmp(name, names[i]) == 0) e->fault = (enum fault)i;
  if ((int)e->fault < 0) {
    set_error(error, error_size, "fault engine: unknown fault (none, penetrate, tangential, distance, energy, nan, tunnel)");
    free(e);
    return NULL;
  }
  if (gauss6_config_value(config, "at", value, sizeof value)) e->at = strtod(value, NULL);
  e->jump[2] = -0.18;
  if (gauss6_config_value(config, "jump", value, sizeof value) &&
      sscanf(value, "%lf,%lf,%lf", &e->jump[0], &e->jump[1], &e->jump[2]) != 3) {
    set_error(error, error_size, "fault engine: jump must be X,Y,Z");
    free(e);
    return NULL;
  }
  e->kick_tick = -1;
  e->library = dlopen(path, RTLD_NOW | RTLD_LOCAL);
  gauss6_engine_get_fn get = e->library ? (gauss6_engine_get_fn)dlsym(e->library, GAUSS6_ENGINE_ENTRY) : NULL;
  e->inner = get ? (const gauss6_engine_v1*)get(GAUSS6_ENGINE_ABI_VERSION) : NULL;
  if (!e->inner) {
    set_error(error, error_size, "fault engine: cannot load the inner engine's version 1 table");
    if (e->library) dlclose(e->library);
    free(e);
    return NULL;
  }
  e->inner_engine = e->inner->create("", error, error_size);
  if (!e->inner_engine) {
    dlclose(e->library);
    free(e);
    return NULL;
  }
  return e;
}

static int reset(void* handle, const gauss6_scene_desc* s, char* error, size_t error_size) {
  engine* e = (engine*)handle;
  e->delta = s->delta;
  e->done = 0;
  e->had_contacts = 0;
  e->kick_tick = -1;
  return e->inner->reset(e->inner_engine, s, error, error_size);
}

static double norm3(const double* v) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

static int step(void* handle, double t, const gauss6_pose* X_WH, gauss6_step_out* out) {
  engine* e = (engine*)handle;
  /* The inner engine needs its contacts: give it a buffer when the caller has none. */
  gauss6_contact local[64];
  const int own = out->contact_capacity <= 0 || !out->contacts;
  gauss6_step_out in = *out;
  if (own) in.contacts = local, in.contact_capacity = 64;
  if (e->inner->step(e->inner_engine, t, X_WH, &in) != GAUSS6_ENGINE_OK) {
    snprintf(e->error, sizeof e->error, "%s", e->inner->last_error(e->inner_engine));
    return GAUSS6_ENGINE_ERROR;
  }
  const int has_contacts = in.num_contacts > 0;
  const double* n = has_contacts ? in.contacts[0].normal : NULL;
  const double force = norm3(in.wrench);
  const int active = t >= e->at;

  switch (e->fault) {
    case kNone: break;
    case kPenetrate:
      if (active && !e->done && has_contacts) {
        const double d = 1e-4 + in.contacts[0].separation;
        for (int c = 0; c < 3; ++c) in.X_WS.p[c] -= d * n[c];
        e->done = 1;
      }
      break;
    case kTangential:
      if (active && has_contacts && force > 0) {
        /* A unit tangent: n x (the axis least aligned with n). */
        const int a = fabs(n[0]) < fabs(n[1]) ? (fabs(n[0]) < fabs(n[2]) ? 0 : 2) : (fabs(n[1]) < fabs(n[2]) ? 1 : 2);
        double axis[3] = {0, 0, 0}, u[3];
        axis[a] = 1;
        u[0] = n[1] * axis[2] - n[2] * axis[1];
        u[1] = n[2] * axis[0] - n[0] * axis[2];
        u[2] = n[0] * axis[1] - n[1] * axis[0];
        const double len = norm3(u);
        for (int c = 0; c < 3; ++c) in.wrench[c] += 0.05 * force * u[c] / len;
      }
      break;
    case kDistance:
      if (active && !e->done && has_contacts && force > 0) {
        for (int c = 0; c < 3; ++c) in.X_WS.p[c] += 10 * e->delta * n[c];
        e->done = 1;
      }
      break;
    case kEnergy: {
      /* Armed by a new contact; the push starts once the contact carries 1 N. */
      if (active && has_contacts && !e->had_contacts) e->kick_tick = -2;
      if (e->kick_tick == -2 && has_contacts && force >= 1.0) e->kick_tick = 0;
      if (!has_contacts && e->kick_tick == -2) e->kick_tick = -1;
      if (e->kick_tick >= 0 && e->kick_tick < 40 && has_contacts && force > 0) {
        const int k = e->kick_tick;
        /* N: 0.1, 0.2, .. 2.0, 2.0, 1.9, .. 0.1, and never above the inner force, so that the push
           dies out with it when the contact ends (no jump, no force once the contact is gone). */
        const double ramp = 0.1 * (k < 20 ? k + 1 : 40 - k);
        const double c = ramp < force ? ramp : force;
        const double* I = in.contacts[0].point;
        const double arm[3] = {I[0] - in.X_WS.p[0], I[1] - in.X_WS.p[1], I[2] - in.X_WS.p[2]};
        for (int i = 0; i < 3; ++i) in.wrench[i] += c * n[i];
        in.wrench[3] += c * (arm[1] * n[2] - arm[2] * n[1]);
        in.wrench[4] += c * (arm[2] * n[0] - arm[0] * n[2]);
        in.wrench[5] += c * (arm[0] * n[1] - arm[1] * n[0]);
      }
      if (e->kick_tick >= 0 && e->kick_tick < 40) ++e->kick_tick;
      break;
    }
    case kNan:
      if (active && !e->done) {
        in.wrench[0] = NAN;
        e->done = 1;
      }
      break;
    case kTunnel:
      if (active && !e->done && !has_contacts) {
        for (int c = 0; c < 3; ++c) in.X_WS.p[c] += e->jump[c];
        e->done = 1;
      }
      break;
  }
  e->had_contacts = has_contacts;
  if (own) in.contacts = out->contacts, in.contact_capacity = out->contact_capacity, in.num_contacts = -1;
  *out = in;
  return GAUSS6_ENGINE_OK;
}

static const char* last_error(void* handle) { return ((engine*)handle)->error; }

static void destroy(void* handle) {
  engine* e = (engine*)handle;
  if (!e) return;
  e->inner->destroy(e->inner_engine);
  dlclose(e->library);
  free(e);
}

static const gauss6_engine_v1 kTable = {
    GAUSS6_ENGINE_ABI_VERSION, sizeof(gauss6_engine_v1), sizeof(gauss6_scene_desc), sizeof(gauss6_step_out),
    "fault engine (test)", create, reset, step, last_error, destroy,
};

GAUSS6_EXPORT const void* gauss6_engine_get(uint32_t abi_version) {
  return abi_version == GAUSS6_ENGINE_ABI_VERSION ? &kTable : NULL;
}
