/* A test engine that misbehaves on purpose, for the tests of the engine's
 * isolation and of the loader (python/tests/test_engine_isolation.py): each
 * misbehaviour must end `gauss6 validate` with a report, a check engine_failure
 * naming it, and exit status 2 (docs/engine-contract.md), never a crash, a hang,
 * a traceback or a pass.
 *
 * Built several times (engine/CMakeLists.txt). The plain build speaks version 2
 * (declarations) and misbehaves as its config says; the other builds carry one
 * malformed table or library, chosen at compile time:
 *   GAUSS6_PROBE_NULL_POINTERS    a table whose function pointers are NULL
 *   GAUSS6_PROBE_WRONG_VERSION    the version 1 table whatever version is asked for
 *   GAUSS6_PROBE_DATA_ENTRY       gauss6_engine_get is an array of bytes, not a function
 *   GAUSS6_PROBE_CONSTRUCTOR_EXIT the library's constructor calls exit(0) at load
 *
 * Otherwise the engine displays the handle's pose, sends no wrench and reports no
 * contacts. Config (gauss6/engine_config.h): probe=NAME, at=TICK (the step at which
 * a step's probe acts, default 0), declare_mu=MU, declare_latency=N, declare_skin=S
 * (declared when given). Probes:
 *   exit_create abort_create hang_create   create calls exit(0), abort(), or sleeps
 *   exit_reset                             reset calls exit(0)
 *   exit_step abort_step segv_step hang_step   the step at `at` calls exit(0), abort(),
 *                                          writes through a NULL pointer, or sleeps
 *   error_step                             the step at `at` returns an error status
 *   overflow_out                           the step at `at` writes a double past *out
 *   overflow_contacts                      ... writes one contact past the buffer's capacity
 *   nan_pose huge_pose                     ... displays a NaN, or a 1e300 m, position
 *   nan_time negative_time                 ... reports a NaN, or -0.5 s, step time
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gauss6/engine.h"
#include "gauss6/engine_config.h"

#define GAUSS6_EXPORT __attribute__((visibility("default")))

typedef struct engine {
  char probe[64];
  long at;
  long tick;
  gauss6_declarations declared;
  char error[256];
} engine;

static int is(const engine* e, const char* probe) { return strcmp(e->probe, probe) == 0; }

static void* create(const char* config, char* error, size_t error_size) {
  static const char* const keys[] = {"probe", "at", "declare_mu", "declare_latency", "declare_skin", NULL};
  if (gauss6_config_check(config, keys, "probe engine", error, error_size) != 0) return NULL;
  engine* e = (engine*)calloc(1, sizeof(engine));
  if (!e) return NULL;
  char value[64];
  gauss6_config_value(config, "probe", e->probe, sizeof e->probe);
  if (gauss6_config_value(config, "at", value, sizeof value)) e->at = strtol(value, NULL, 10);
  if (gauss6_config_value(config, "declare_mu", value, sizeof value))
    e->declared.flags |= GAUSS6_DECLARE_FRICTION, e->declared.friction_mu = strtod(value, NULL);
  if (gauss6_config_value(config, "declare_latency", value, sizeof value))
    e->declared.flags |= GAUSS6_DECLARE_LATENCY, e->declared.latency_ticks = (int32_t)strtol(value, NULL, 10);
  if (gauss6_config_value(config, "declare_skin", value, sizeof value))
    e->declared.flags |= GAUSS6_DECLARE_SKIN, e->declared.skin = strtod(value, NULL);
  if (is(e, "exit_create")) exit(0);
  if (is(e, "abort_create")) abort();
  if (is(e, "hang_create"))
    for (;;) sleep(1);
  return e;
}

static int reset(void* handle, const gauss6_scene_desc* s, char* error, size_t error_size) {
  engine* e = (engine*)handle;
  (void)s, (void)error, (void)error_size;
  if (is(e, "exit_reset")) exit(0);
  e->tick = 0;
  return GAUSS6_ENGINE_OK;
}

static int step(void* handle, double t, const gauss6_pose* X_WH, gauss6_step_out* out) {
  engine* e = (engine*)handle;
  (void)t;
  out->X_WS = *X_WH;
  memset(out->wrench, 0, sizeof out->wrench);
  out->num_contacts = 0;
  if (e->tick++ != e->at || !e->probe[0]) return GAUSS6_ENGINE_OK;
  if (is(e, "exit_step")) exit(0);
  if (is(e, "abort_step")) abort();
  if (is(e, "segv_step")) {
    volatile int* volatile nowhere = NULL;
    *nowhere = 1;
  }
  if (is(e, "hang_step"))
    for (;;) sleep(1);
  if (is(e, "error_step")) {
    snprintf(e->error, sizeof e->error, "probe engine: a planted error");
    return GAUSS6_ENGINE_ERROR;
  }
  if (is(e, "overflow_out")) ((volatile double*)(out + 1))[1] = 1.0;
  if (is(e, "overflow_contacts") && out->contacts) out->contacts[out->contact_capacity].separation = 1.0;
  if (is(e, "nan_pose")) out->X_WS.p[0] = NAN;
  if (is(e, "huge_pose")) out->X_WS.p[2] = 1e300;
  if (is(e, "nan_time")) out->step_seconds = NAN;
  if (is(e, "negative_time")) out->step_seconds = -0.5;
  return GAUSS6_ENGINE_OK;
}

static const char* last_error(void* handle) { return ((engine*)handle)->error; }

static void destroy(void* handle) { free(handle); }

static int declare(void* handle, gauss6_declarations* out) {
  const engine* e = (const engine*)handle;
  out->flags = e->declared.flags;
  out->friction_mu = e->declared.friction_mu;
  out->latency_ticks = e->declared.latency_ticks;
  out->skin = e->declared.skin;
  return GAUSS6_ENGINE_OK;
}

#if defined(GAUSS6_PROBE_NULL_POINTERS)
static const gauss6_engine_v1 kTable = {
    GAUSS6_ENGINE_ABI_VERSION, sizeof(gauss6_engine_v1), sizeof(gauss6_scene_desc), sizeof(gauss6_step_out),
    "probe engine (NULL pointers)", NULL, NULL, NULL, NULL, NULL,
};
GAUSS6_EXPORT const void* gauss6_engine_get(uint32_t abi_version) {
  (void)create, (void)reset, (void)step, (void)last_error, (void)destroy, (void)declare;
  return abi_version == GAUSS6_ENGINE_ABI_VERSION ? &kTable : NULL;
}
#elif defined(GAUSS6_PROBE_WRONG_VERSION)
static const gauss6_engine_v1 kTable = {
    GAUSS6_ENGINE_ABI_VERSION, sizeof(gauss6_engine_v1), sizeof(gauss6_scene_desc), sizeof(gauss6_step_out),
    "probe engine (any version)", create, reset, step, last_error, destroy,
};
GAUSS6_EXPORT const void* gauss6_engine_get(uint32_t abi_version) {
  (void)abi_version, (void)declare;
  return &kTable;
}
#elif defined(GAUSS6_PROBE_DATA_ENTRY)
GAUSS6_EXPORT const unsigned char gauss6_engine_get[64] = {0};
const void* probe_unused[] = {(const void*)create, (const void*)reset, (const void*)step, (const void*)last_error,
                              (const void*)destroy, (const void*)declare};
#else
#if defined(GAUSS6_PROBE_CONSTRUCTOR_EXIT)
__attribute__((constructor)) static void leave(void) { exit(0); }
#endif
static const gauss6_engine_v2 kTable = {
    {GAUSS6_ENGINE_ABI_VERSION_2, sizeof(gauss6_engine_v2), sizeof(gauss6_scene_desc), sizeof(gauss6_step_out),
     "probe engine", create, reset, step, last_error, destroy},
    declare,
};
GAUSS6_EXPORT const void* gauss6_engine_get(uint32_t abi_version) {
  return abi_version == GAUSS6_ENGINE_ABI_VERSION_2 ? &kTable : NULL;
}
#endif
