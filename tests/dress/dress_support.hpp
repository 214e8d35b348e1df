#pragma once
// Shared by the dressing tests: one cache of the default bodies for the whole test program (an
// inline function's statics are one object across translation units) and the failed-gate message.
#include <cstdlib>
#include <string>

#include "drape/dress.hpp"
#include "support/test_support.hpp"

namespace drape::test {

// Bodies are expensive to build: one of each per test program, made on first use (thread-safe
// statics, one per sex and per `make`).
template <class Make>
const Body& once_per_sex(Sex sex, Make make) {
  if (sex == Sex::Male) {
    static const Body male = make(Sex::Male);
    return male;
  }
  static const Body female = make(Sex::Female);
  return female;
}

inline const Body& cached_body(Sex sex) {
  return once_per_sex(sex, [](Sex s) { return default_body(s); });
}

// The parametric generator's average adult (the default body before MakeHuman's), for tests of
// the explicit step's own settings, whose measured effects were found on it (~1 s to make, once).
inline const Body& generator_body(Sex sex) {
  return once_per_sex(sex, [](Sex s) { return generate_default_body(s); });
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
