// The engine C ABI from C++, as a third party loads it: dlopen a library by path, take its
// version 1 table from gauss6_engine_get, check the struct sizes, create, reset on a scene
// description (meshes in memory, no scene file), step a few hundred ticks, destroy. Run on
// the example engine (C) and on gauss6's own engine, with the same scene and hand motion:
// a 2 cm cube tool lowered onto a 10 cm cube obstacle and pressed 1 cm past its top. And the
// version 2 table: a version 2 engine's declarations; a version 1 engine answers NULL for 2.
#include <dlfcn.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "gauss6/engine.h"

namespace {

struct Cube {
  std::vector<double> V;
  std::vector<int32_t> F;
};

// An axis-aligned cube of half-size h centred on the origin, 12 outward triangles.
Cube cube(double h) {
  Cube c;
  for (int i = 0; i < 8; ++i) {
    c.V.push_back(i & 1 ? h : -h);
    c.V.push_back(i & 2 ? h : -h);
    c.V.push_back(i & 4 ? h : -h);
  }
  c.F = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  return c;
}

struct Library {
  void* handle = nullptr;
  const gauss6_engine_v1* table = nullptr;
  explicit Library(const char* path) {
    handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!handle) return;
    auto get = reinterpret_cast<gauss6_engine_get_fn>(dlsym(handle, "gauss6_engine_get"));
    if (get) table = static_cast<const gauss6_engine_v1*>(get(GAUSS6_ENGINE_ABI_VERSION));
  }
  ~Library() {
    if (handle) dlclose(handle);
  }
};

struct Run {
  std::vector<double> fz, xs_z;
  int steps = 0;
};

// 400 ticks at 1 kHz: the handle at the start pose for 50 ticks, lowered 2 cm over 200
// ticks (the tool's bottom from 1 cm above the obstacle's top to 1 cm below it), then held.
Run drive(const char* path, const char* config) {
  Library lib(path);
  INFO(path << ": " << (lib.handle ? "" : dlerror()));
  REQUIRE(lib.handle);
  REQUIRE(lib.table);
  const gauss6_engine_v1& t = *lib.table;
  REQUIRE(t.abi_version == GAUSS6_ENGINE_ABI_VERSION);
  REQUIRE(t.table_size == sizeof(gauss6_engine_v1));
  REQUIRE(t.scene_desc_size == sizeof(gauss6_scene_desc));
  REQUIRE(t.step_out_size == sizeof(gauss6_step_out));
  REQUIRE(t.name != nullptr);
  char error[512] = "";
  void* engine = t.create(config, error, sizeof error);
  INFO("create: " << error);
  REQUIRE(engine);

  const Cube obstacle = cube(0.05), tool = cube(0.01);
  gauss6_body box{"box", {obstacle.V.data(), 8, obstacle.F.data(), 12}, {{0, 0, 0}, {1, 0, 0, 0}}};
  gauss6_scene_desc scene{};
  scene.struct_size = sizeof scene;
  scene.name = "cube on a box";
  scene.scene_path = "";
  scene.length_unit_m = 1;
  scene.num_obstacles = 1;
  scene.obstacles = &box;
  scene.tool = gauss6_body{"tool", {tool.V.data(), 8, tool.F.data(), 12}, {{0, 0, 0.07}, {1, 0, 0, 0}}};
  scene.mass = 0.0628;  // 2 cm steel cube
  const double I = scene.mass * (0.02 * 0.02 + 0.02 * 0.02) / 12;
  const double inertia[9] = {I, 0, 0, 0, I, 0, 0, 0, I};
  std::memcpy(scene.inertia_G_B, inertia, sizeof inertia);
  scene.delta = 1e-6;
  scene.rate_hz = 1000;
  scene.max_force = 20;
  scene.max_torque = 1;
  scene.ks = 0.5;
  scene.kh = 4000;
  INFO("reset: " << error);
  REQUIRE(t.reset(engine, &scene, error, sizeof error) == GAUSS6_ENGINE_OK);

  Run run;
  std::vector<gauss6_contact> contacts(64);
  for (int k = 0; k < 400; ++k) {
    const double time = k / 1000.0;
    const double lowered = std::min(std::max(time - 0.05, 0.0), 0.2) * 0.1;
    gauss6_pose handle{{0, 0, 0.07 - lowered}, {1, 0, 0, 0}};
    gauss6_step_out out{};
    out.struct_size = sizeof out;
    out.contact_capacity = static_cast<int32_t>(contacts.size());
    out.contacts = contacts.data();
    const int status = t.step(engine, time, &handle, &out);
    INFO("step at " << time << ": " << t.last_error(engine));
    REQUIRE(status == GAUSS6_ENGINE_OK);
    for (double w : out.wrench) REQUIRE(std::isfinite(w));
    REQUIRE(out.num_contacts <= out.contact_capacity);
    run.fz.push_back(out.wrench[2]);
    run.xs_z.push_back(out.X_WS.p[2]);
    ++run.steps;
  }
  t.destroy(engine);
  return run;
}

}  // namespace

TEST_CASE("the example engine, loaded by path, pushes the pressed tool up", "[engine][abi]") {
  const Run run = drive(GAUSS6_BOX_PENALTY_ENGINE_PATH, "stiffness=2000");
  REQUIRE(run.steps == 400);
  // Free for the first 50 ticks (1 cm above the box): no force.
  for (int k = 0; k < 50; ++k) REQUIRE(run.fz[k] == 0.0);
  // Held 1 cm inside: about 2000 N/m * 1 cm = 20 N up (its spring; at least 1 N).
  REQUIRE(run.fz.back() > 1.0);
}

TEST_CASE("gauss6's engine, loaded by path, stops the tool on the box and pushes back", "[engine][abi]") {
  const Run run = drive(GAUSS6_ENGINE_PATH, "");
  REQUIRE(run.steps == 400);
  for (int k = 0; k < 50; ++k) REQUIRE(run.fz[k] == 0.0);
  // The displayed cube never goes below the box's top (its bottom is 1 cm under G), and the
  // hand 1 cm past it feels the coupling's force up: kh ks m * 1 cm = 1.26 N (at least 0.5 N).
  for (double z : run.xs_z) REQUIRE(z - 0.01 > 0.05);
  REQUIRE(run.fz.back() > 0.5);
}

TEST_CASE("a version 2 table declares, and a version 1 engine answers NULL for version 2", "[engine][abi]") {
  void* probe = dlopen(GAUSS6_PROBE_ENGINE_PATH, RTLD_NOW | RTLD_LOCAL);
  REQUIRE(probe);
  auto get = reinterpret_cast<gauss6_engine_get_fn>(dlsym(probe, GAUSS6_ENGINE_ENTRY));
  REQUIRE(get);
  REQUIRE(get(GAUSS6_ENGINE_ABI_VERSION) == nullptr);  // it speaks 2 only
  const auto* t = static_cast<const gauss6_engine_v2*>(get(GAUSS6_ENGINE_ABI_VERSION_2));
  REQUIRE(t);
  REQUIRE(t->v1.abi_version == GAUSS6_ENGINE_ABI_VERSION_2);
  REQUIRE(t->v1.table_size == sizeof(gauss6_engine_v2));
  REQUIRE(t->declare);
  char error[256] = "";
  void* engine = t->v1.create("declare_mu=0.3;declare_latency=2", error, sizeof error);
  INFO("create: " << error);
  REQUIRE(engine);
  gauss6_declarations d{};
  d.struct_size = sizeof d;
  REQUIRE(t->declare(engine, &d) == GAUSS6_ENGINE_OK);
  REQUIRE(d.flags == (GAUSS6_DECLARE_FRICTION | GAUSS6_DECLARE_LATENCY));
  REQUIRE(d.friction_mu == 0.3);
  REQUIRE(d.latency_ticks == 2);
  t->v1.destroy(engine);
  // An unknown config key is refused, named.
  REQUIRE(t->v1.create("declare_nu=0.3", error, sizeof error) == nullptr);
  REQUIRE(std::string(error).find("'declare_nu=0.3'") != std::string::npos);
  dlclose(probe);

  void* v1 = dlopen(GAUSS6_BOX_PENALTY_ENGINE_PATH, RTLD_NOW | RTLD_LOCAL);
  REQUIRE(v1);
  auto get1 = reinterpret_cast<gauss6_engine_get_fn>(dlsym(v1, GAUSS6_ENGINE_ENTRY));
  REQUIRE(get1);
  REQUIRE(get1(GAUSS6_ENGINE_ABI_VERSION_2) == nullptr);
  REQUIRE(get1(GAUSS6_ENGINE_ABI_VERSION) != nullptr);
  dlclose(v1);
}

TEST_CASE("gauss6's engine speaks both versions and declares the latency of a slower sim step", "[engine][abi]") {
  void* lib = dlopen(GAUSS6_ENGINE_PATH, RTLD_NOW | RTLD_LOCAL);
  REQUIRE(lib);
  auto get = reinterpret_cast<gauss6_engine_get_fn>(dlsym(lib, GAUSS6_ENGINE_ENTRY));
  REQUIRE(get);
  REQUIRE(get(GAUSS6_ENGINE_ABI_VERSION) != nullptr);
  const auto* t = static_cast<const gauss6_engine_v2*>(get(GAUSS6_ENGINE_ABI_VERSION_2));
  REQUIRE(t);
  REQUIRE(t->v1.table_size == sizeof(gauss6_engine_v2));
  REQUIRE(t->declare);
  char error[256] = "";
  for (int period : {1, 2, 8}) {
    void* engine = t->v1.create(("sim_period=" + std::to_string(period)).c_str(), error, sizeof error);
    INFO("sim_period " << period << ": " << error);
    REQUIRE(engine);
    gauss6_declarations d{};
    d.struct_size = sizeof d;
    REQUIRE(t->declare(engine, &d) == GAUSS6_ENGINE_OK);
    // At sim_period 1 nothing is declared; above it, the crossing is answered 2 (period - 1) ticks later.
    REQUIRE(d.flags == (period > 1 ? GAUSS6_DECLARE_LATENCY : 0u));
    if (period > 1) REQUIRE(d.latency_ticks == 2 * (period - 1));
    t->v1.destroy(engine);
  }
  dlclose(lib);
}
