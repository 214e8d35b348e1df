#pragma once
// Shared by the dressing tests: one cache of the default bodies for the whole test program (an
// inline function's statics are one object across translation units) and the failed-gate message.
#include <cstdlib>
#include <map>
#include <mutex>
#include <string>

#include "drape/dress.hpp"

namespace drape::test {

inline bool sanitized() { return std::getenv("DRAPE_SANITIZED") != nullptr; }

// Bodies are expensive to build: one of each per test program.
inline const Body& cached_body(Sex sex) {
  static std::map<Sex, Body> bodies;
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  auto it = bodies.find(sex);
  if (it == bodies.end()) it = bodies.emplace(sex, default_body(sex)).first;
  return it->second;
}

// The parametric generator's average adult (the default body before MakeHuman's), for tests of
// the explicit step's own settings, whose measured effects were found on it (~1 s to make, once).
inline const Body& generator_body(Sex sex) {
  static std::map<Sex, Body> bodies;
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  auto it = bodies.find(sex);
  if (it == bodies.end()) it = bodies.emplace(sex, generate_default_body(sex)).first;
  return it->second;
}

// Options for the paper's explicit step (--solver explicit), for tests of its own settings.
inline DressOptions explicit_options() {
  DressOptions o;
  o.solver = Solver::Explicit;
  return o;
}

inline std::string failed_gates(const DressResult& r) {
  std::string s;
  for (const GateResult& g : r.gates)
    if (!g.passed) s += g.name + " (" + g.detail + "); ";
  return s;
}

}  // namespace drape::test
