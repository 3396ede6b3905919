/* The engine contract, C ABI: what an engine under test (a six-DoF haptic
 * rendering step: a god-object, proxy or virtual-coupling tool) exports so that
 * gauss6 can drive it, record it and judge it without linking it (docs/engine-contract.md).
 *
 * Plain C (C99), no C++ type crosses it. An engine is a shared library that
 * exports one function, GAUSS6_ENGINE_ENTRY ("gauss6_engine_get"): given the ABI
 * version the caller speaks, it returns its table of function pointers for that
 * version (or NULL). The table states the sizes of the structs the engine was
 * compiled with, so that a caller refuses a mismatched engine instead of reading
 * past a struct.
 *
 * Versions: 1 (gauss6_engine_v1) and 2 (gauss6_engine_v2: version 1's table
 * followed by an optional `declare`, what the engine renders on purpose). gauss6
 * asks for 2 first and for 1 when an engine answers NULL, so a version-1 engine
 * keeps working unchanged; a table whose abi_version is not the one asked for is
 * refused.
 *
 * Units and frames: the scene's units (metres, kilograms, seconds in the shipped
 * scenes; length_unit_m says so), world frame W. A pose is (p, q): p in R^3 the
 * position of the body's reference point G, q = (w, x, y, z) a quaternion, not
 * necessarily unit; a body point r_B maps to p + R(q) r_B with R(q) the rotation
 * of q / |q| (METHOD.md section 1). Wrenches are (force, torque about G), N and
 * N m, world frame: the wrench the engine sends to the user's handle.
 *
 * Calls: create once; reset before the first step and for every new run; step
 * once per haptic tick (the caller's clock, 1 kHz in the shipped scenes), with
 * t strictly increasing from 0 after a reset; destroy once. The caller never
 * calls one engine from two threads at a time. Strings and arrays the caller
 * passes live for the duration of the call only: an engine copies what it keeps.
 */
#ifndef GAUSS6_ENGINE_H
#define GAUSS6_ENGINE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define GAUSS6_ENGINE_ABI_VERSION 1   /* version 1: gauss6_engine_v1 */
#define GAUSS6_ENGINE_ABI_VERSION_2 2 /* version 2: gauss6_engine_v2 (declarations) */
#define GAUSS6_ENGINE_ENTRY "gauss6_engine_get"

/* A pose of a body frame B in the world W: p (scene length units), q = (w, x, y, z). */
typedef struct gauss6_pose {
  double p[3];
  double q[4];
} gauss6_pose;

/* A closed triangle mesh in its body frame B: vertices num_vertices x 3 (row-major,
 * scene length units), faces num_faces x 3 vertex indices (0-based), counter-clockwise
 * seen from outside (outward normals). */
typedef struct gauss6_mesh {
  const double* vertices;
  int32_t num_vertices;
  const int32_t* faces;
  int32_t num_faces;
} gauss6_mesh;

/* A body: its name, its mesh (body frame) and the pose X_WB of that frame. */
typedef struct gauss6_body {
  const char* name;
  gauss6_mesh mesh;
  gauss6_pose X_WB;
} gauss6_body;

/* The scene an engine renders (reset). Obstacles are static; the tool is the
 * object the user holds (the god-object), its mesh in its body frame whose origin
 * is G, so that a displayed pose X_WS places it. */
typedef struct gauss6_scene_desc {
  uint32_t struct_size;             /* sizeof(gauss6_scene_desc) of the caller */
  const char* name;                 /* the scene's name */
  const char* scene_path;           /* the gauss6 scene file (TOML) it came from; may be "" */
  double length_unit_m;             /* metres per scene length unit (1 in the shipped scenes) */
  int32_t num_obstacles;
  const gauss6_body* obstacles;     /* num_obstacles static bodies */
  gauss6_body tool;                 /* mesh in B (origin at G); X_WB: its initial pose */
  double mass;                      /* kg */
  double inertia_G_B[9];            /* kg m^2, about G, body frame B, row-major */
  double delta;                     /* the scene's separation (length units): METHOD.md s.4 */
  double rate_hz;                   /* the haptic tick's rate (Hz) */
  double max_force, max_torque;     /* N, N m: what the device renders */
  double ks, kh;                    /* the scene's god-object gains (METHOD.md s.2-3); others may ignore them */
} gauss6_scene_desc;

/* One contact the engine reports: point on the tool (world frame), unit normal out
 * of the obstacle towards the tool, separation (length units; negative: penetration). */
typedef struct gauss6_contact {
  double point[3];
  double normal[3];
  double separation;
} gauss6_contact;

/* What a step returns. The caller sets struct_size, contact_capacity and contacts
 * (a buffer of contact_capacity entries, may be NULL with capacity 0) before the call. */
typedef struct gauss6_step_out {
  uint32_t struct_size;             /* sizeof(gauss6_step_out) of the caller */
  gauss6_pose X_WS;                 /* the displayed pose of the tool (its G and orientation) */
  double wrench[6];                 /* force (N), torque about G (N m), world frame, sent to the user */
  int32_t num_contacts;             /* contacts written (<= contact_capacity); -1: not reported */
  int32_t contact_capacity;         /* set by the caller */
  gauss6_contact* contacts;         /* set by the caller */
  double step_seconds;              /* the engine's own wall time for this step (s); the caller sets -1:
                                       left at -1, not reported; NaN or another negative value is refused */
} gauss6_step_out;

/* Status of a call: 0 is success; anything else is an error whose text the engine
 * wrote into the caller's error buffer (reset) or keeps for last_error (step). */
enum { GAUSS6_ENGINE_OK = 0, GAUSS6_ENGINE_ERROR = 1 };

/* The version 1 table. */
typedef struct gauss6_engine_v1 {
  uint32_t abi_version;             /* GAUSS6_ENGINE_ABI_VERSION (1) */
  uint32_t table_size;              /* sizeof(gauss6_engine_v1) */
  uint32_t scene_desc_size;         /* sizeof(gauss6_scene_desc) the engine was compiled with */
  uint32_t step_out_size;           /* sizeof(gauss6_step_out) */
  const char* name;                 /* e.g. "gauss6 0.2 (god-object)" */

  /* A new engine; config is engine-specific text ("" for the defaults, never NULL).
   * NULL on failure, with the reason in error[0 .. error_size). */
  void* (*create)(const char* config, char* error, size_t error_size);
  /* Loads a scene and puts the tool at its initial pose, at rest, with no force. */
  int (*reset)(void* engine, const gauss6_scene_desc* scene, char* error, size_t error_size);
  /* One haptic tick at time t (s) with the handle's pose X_WH: fills *out. */
  int (*step)(void* engine, double t, const gauss6_pose* X_WH, gauss6_step_out* out);
  /* The text of the last failed call (never NULL; "" if none). */
  const char* (*last_error)(void* engine);
  void (*destroy)(void* engine);
} gauss6_engine_v1;

/* What an engine renders on purpose (version 2), so that the oracle judges it as
 * declared (docs/engine-contract.md, "Declarations"): the caller zeroes the struct
 * and sets struct_size; the engine sets a flag for each field it declares. */
enum {
  GAUSS6_DECLARE_FRICTION = 1u << 0, /* Coulomb friction with coefficient friction_mu (>= 0) */
  GAUSS6_DECLARE_LATENCY = 1u << 1,  /* its force responds latency_ticks (>= 0) haptic ticks late */
  GAUSS6_DECLARE_SKIN = 1u << 2      /* it keeps a separation of skin (length units, >= 0) from obstacles */
};

typedef struct gauss6_declarations {
  uint32_t struct_size;             /* sizeof(gauss6_declarations) of the caller */
  uint32_t flags;                   /* GAUSS6_DECLARE_* of the fields set */
  double friction_mu;
  int32_t latency_ticks;
  double skin;
} gauss6_declarations;

/* The version 2 table: version 1's (its abi_version 2, its table_size
 * sizeof(gauss6_engine_v2)), then `declare`, which may be NULL (nothing declared). */
typedef struct gauss6_engine_v2 {
  gauss6_engine_v1 v1;
  /* Fills *out after create (before any reset); returns GAUSS6_ENGINE_OK. */
  int (*declare)(void* engine, gauss6_declarations* out);
} gauss6_engine_v2;

/* The one exported symbol: the table for abi_version, or NULL when the engine
 * does not speak it. The table is static: it lives as long as the library. */
typedef const void* (*gauss6_engine_get_fn)(uint32_t abi_version);

#ifdef __cplusplus
}
#endif

#endif /* GAUSS6_ENGINE_H */
