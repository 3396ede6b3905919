// Data the benchmark fixtures own, loaded once per process (load time: these
// functions allocate and throw): the rigid CCD step sets of datasets_generated/ccd/
// (README.md there: one obstacle in the world frame, a god-object mesh in its own
// frame with G at `offset`, poses X0 -> X1 of G), with their meshes and BVHs built
// at a chosen leaf size. The Python sweeps (python/gauss6/sweeps.py) read the same
// files, so that speed measured here and error measured there are on the same data.
#pragma once

#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gauss6/bvh.h"
#include "gauss6/mesh_io.h"
#include "gauss6/pose.h"

namespace gauss6::bench {

// The repository whose data the fixtures read: GAUSS6_BENCH_DATA_ROOT when set
// (the gate points both revisions' builds at the same data), else the source tree.
inline std::string data_root() {
  const char* env = std::getenv("GAUSS6_BENCH_DATA_ROOT");
  return env && *env ? std::string(env) : std::string(GAUSS6_SOURCE_DIR);
}
inline std::string datasets_dir() { return data_root() + "/datasets_generated"; }
// The shared test data (../shared/data beside the repository).
inline std::string shared_data_dir() { return data_root() + "/../shared/data"; }

// One step of a set: X0 -> X1, poses of G (q as stored: not necessarily unit).
struct CcdSetStep {
  std::string id;
  int pair = 0;  // index into CcdSet::pairs
  Pose x0, x1;
};

// One obstacle (world frame) and one god-object (body frame, origin at G), with BVHs.
struct CcdMeshPair {
  TriangleMesh obstacle, god;
  Bvh obstacle_bvh, god_bvh;
  CcdBody obstacle_body() const { return {&obstacle, &obstacle_bvh}; }
  CcdBody god_body() const { return {&god, &god_bvh}; }
};

struct CcdSet {
  std::string name;
  double delta = 0;  // the set's separation delta (scene units)
  int leaf_size = 4;
  std::vector<std::unique_ptr<CcdMeshPair>> pairs;
  std::vector<CcdSetStep> steps;
};

inline Pose pose_of(const nlohmann::json& p, const nlohmann::json& q) {
  return {Vec3(p[0].get<double>(), p[1].get<double>(), p[2].get<double>()),
          Quat{q[0].get<double>(), q[1].get<double>(), q[2].get<double>(), q[3].get<double>()}};
}

// Reads datasets_generated/ccd/<name>.json; BVHs built with leaf_size.
inline std::unique_ptr<CcdSet> load_ccd_set(const std::string& name, int leaf_size) {
  const std::string path = datasets_dir() + "/ccd/" + name + ".json";
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  const nlohmann::json doc = nlohmann::json::parse(in);
  if (doc.at("format") != "gauss6-ccd-steps" || doc.at("version") != 1)
    throw std::runtime_error(path + ": not a gauss6-ccd-steps version 1 file");
  auto set = std::make_unique<CcdSet>();
  set->name = name;
  set->delta = doc.at("delta").get<double>();
  set->leaf_size = leaf_size;
  std::map<std::string, int> pair_index;  // key: obstacle|god|offset
  for (const auto& s : doc.at("steps")) {
    const std::string key = s.at("obstacle").get<std::string>() + "|" + s.at("god").get<std::string>() + "|" +
                            s.at("offset").dump();
    auto it = pair_index.find(key);
    if (it == pair_index.end()) {
      auto pair = std::make_unique<CcdMeshPair>();
      pair->obstacle = read_mesh(datasets_dir() + "/" + s.at("obstacle").get<std::string>());
      pair->god = read_mesh(datasets_dir() + "/" + s.at("god").get<std::string>());
      const auto& o = s.at("offset");
      const Vec3 offset(o[0].get<double>(), o[1].get<double>(), o[2].get<double>());
      for (Eigen::Index v = 0; v < pair->god.V.rows(); ++v) pair->god.V.row(v) -= offset.transpose();
      pair->obstacle_bvh = build_bvh(pair->obstacle, leaf_size);
      pair->god_bvh = build_bvh(pair->god, leaf_size);
      it = pair_index.emplace(key, static_cast<int>(set->pairs.size())).first;
      set->pairs.push_back(std::move(pair));
    }
    set->steps.push_back({s.at("id").get<std::string>(), it->second, pose_of(s.at("p0"), s.at("q0")),
                          pose_of(s.at("p1"), s.at("q1"))});
  }
  return set;
}

// Cached per (name, leaf size): fixtures share the loaded data within one process.
inline const CcdSet& ccd_set(const std::string& name, int leaf_size = 4) {
  static std::map<std::pair<std::string, int>, std::unique_ptr<CcdSet>> cache;
  auto& slot = cache[{name, leaf_size}];
  if (!slot) slot = load_ccd_set(name, leaf_size);
  return *slot;
}

}  // namespace gauss6::bench
