// The scene of the harness tests: a slab and a 2 cm cube held above it
// (test_scenario.cpp, test_crash_safety.cpp).
#pragma once

#include <catch2/catch.hpp>

#include <string>

#include "../../optimized/tests/mesh_shapes.h"
#include "gauss6/geometry/mass_properties.h"
#include "gauss6/io/scene.h"

namespace gauss6::test {

// Slab 20 x 20 x 2 cm with its top at z = 0; cube of 2 cm (8 g of water) held
// 1 cm above it. kh m = 100 N/m.
inline Scene make_slab_scene() {
  Scene s;
  s.path = "test_scenario (in code)";
  s.name = "cube_on_slab";
  Body slab;
  slab.name = "slab";
  slab.mesh = test::make_box(0.2, 0.2, 0.02, Vec3(0, 0, -0.01));
  s.obstacles.push_back(slab);
  s.god_object.name = "cube";
  s.god_object.role = BodyRole::kGodObject;
  s.god_object.mesh = test::make_box(0.02, 0.02, 0.02);
  s.god_object.pose.p = Vec3(0, 0, 0.02);
  std::string why;
  REQUIRE(compute_mass_properties(s.god_object.mesh, 1000.0, &s.god_mass.mass, &why));
  s.god_mass.density = 1000.0;
  s.gains.ks = 0.5;
  s.gains.kh = 100.0 / s.god_mass.mass.mass;
  s.contact.delta = 1e-6;
  s.contact.offset_eps = -1e-5;
  s.contact.offset_time = 0.05;
  s.device.rate_hz = 1000;
  s.device.script = "press_and_slide";
  return s;
}

}  // namespace gauss6::test
