// The fuzz targets of targets.h: each parser of the project on arbitrary bytes.
#include "targets.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "gauss6/io/ccd_queries.h"
#include "gauss6/io/load_error.h"
#include "gauss6/io/mesh_io.h"
#include "gauss6/io/qp_instances.h"
#include "gauss6/replay_device.h"
#include "gauss6/io/scene.h"
#include "gauss6/simulated_device.h"
#include "gauss6/trace.h"

namespace gauss6::fuzz {
namespace {

namespace fs = std::filesystem;

// A folder of this process's own, holding a closed box mesh for scenes to name.
const fs::path& work_dir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("gauss6_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(d);
    std::ofstream(d / "box.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                                    "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\n"
                                    "f 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
    return d;
  }();
  return dir;
}

std::string write_input(const char* name, const uint8_t* data, size_t size) {
  const fs::path p = work_dir() / name;
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data),
                                                              static_cast<std::streamsize>(size));
  return p.string();
}

void mesh(const char* file, const uint8_t* data, size_t size) {
  try {
    const std::string path = write_input(file, data, size);
    const TriangleMesh m = read_mesh(path);
    validate_mesh(m);
    read_vertex_normals(path);  // as the scene loader does after read_mesh (PLY nx, ny, nz)
  } catch (const LoadError&) {
  }
}

void scene(const uint8_t* data, size_t size) {
  try {
    load_scene(write_input("scene.toml", data, size));
  } catch (const LoadError&) {
  }
}

void trace(const uint8_t* data, size_t size) {
  try {
    const Trace tr = read_trace(write_input("run.g6trace", data, size));
    for (size_t i = 0; i < tr.ticks.num_rows(); ++i) trace_tick(tr, i);
    if (tr.ticks.num_rows()) {
      try {
        ReplayDevice d = ReplayDevice::from_trace(tr, "fuzz");
        DeviceState s;
        d.read(tr.ticks.row(0)[0] + 0.5e-3, &s);
      } catch (const std::invalid_argument&) {  // the replay device's refusal of bad samples
      }
    }
  } catch (const LoadError&) {
  }
}

void ccd_queries(const uint8_t* data, size_t size) {
  try {
    for (const CcdQuery& q : read_ccd_queries(write_input("queries.csv", data, size), CcdQuery::kVertexFace))
      for (const RationalPoint& p : q.points) to_double(p, nullptr);
  } catch (const LoadError&) {
  }
}

void qp_instances(const uint8_t* data, size_t size) {
  try {
    read_qp_instances(write_input("instances.json", data, size));
  } catch (const LoadError&) {
  }
}

void height_map(const uint8_t* data, size_t size) {
  HeightMapImage image;
  std::string error;
  read_height_map(write_input("height.png", data, size), &image, &error);
}

void hand_script(const uint8_t* data, size_t size) {
  try {
    hand_script_from_json(std::string(reinterpret_cast<const char*>(data), size), "script.json");
  } catch (const std::invalid_argument&) {
  }
}

}  // namespace

const std::vector<NamedTarget>& targets() {
  static const std::vector<NamedTarget> all = {
      {"scene", scene},
      {"obj", [](const uint8_t* d, size_t n) { mesh("mesh.obj", d, n); }},
      {"off", [](const uint8_t* d, size_t n) { mesh("mesh.off", d, n); }},
      {"ply", [](const uint8_t* d, size_t n) { mesh("mesh.ply", d, n); }},
      {"stl", [](const uint8_t* d, size_t n) { mesh("mesh.stl", d, n); }},
      {"trace", trace},
      {"ccd_queries", ccd_queries},
      {"qp_instances", qp_instances},
      {"hand_script", hand_script},
      {"height_map", height_map},
  };
  return all;
}

Target find_target(const std::string& name) {
  for (const NamedTarget& t : targets())
    if (name == t.name) return t.run;
  return nullptr;
}

}  // namespace gauss6::fuzz
