// Fabric presets. Every number's source is in docs/fabrics.md; the short form is beside it here.
// Densities are measured values (Wang, Ramamoorthi & O'Brien 2011; Penava et al. 2014); the
// stiffnesses are simulation stiffnesses (see drape/fabric.hpp) whose bending order follows Wang's
// measured bending ranking; thresholds follow the paper's 1-10 % range by fabric type.
#include <array>
#include <cmath>
#include <string>

#include "drape/error.hpp"
#include "drape/fabric.hpp"

namespace drape {
namespace {

Fabric make(std::string name, float density, float warp, float weft, float shear, float bend, float rigidity,
            float threshold, float friction, float thickness) {
  Fabric f;
  f.name = std::move(name);
  f.areal_density = density;
  f.stretch_warp = warp;
  f.stretch_weft = weft;
  f.shear = shear;
  f.bend = bend;
  f.bending_rigidity = rigidity;
  f.strain_threshold = threshold;
  f.friction = friction;
  f.thickness = thickness;
  return f;
}

// name, kg/m^2, warp N/m, weft N/m, shear N/m, bend N/m, bending rigidity N m, threshold, friction, thickness m
const std::array<Fabric, 7>& presets() {
  static const std::array<Fabric, 7> table = {
      // Penava 2014 cotton: 0.1503 kg/m^2, 0.318 mm. Threshold 5 % (the paper's value).
      make("cotton", 0.1503f, 20.0f, 16.0f, 5.0f, 1.0f, 5.5e-5f, 0.05f, 0.30f, 0.000318f),
      // Wang 2011 11oz-black-denim: 0.324 kg/m^2; stiffest bending of Wang's set after two others.
      make("denim", 0.324f, 40.0f, 32.0f, 10.0f, 2.16f, 3.0e-4f, 0.02f, 0.40f, 0.0007f),
      // 19 momme charmeuse: 19 x 4.306 g/m^2 = 0.0818 kg/m^2.
      make("silk", 0.0818f, 10.0f, 9.0f, 2.0f, 0.3f, 3.0e-6f, 0.03f, 0.20f, 0.00015f),
      // Wang 2011 gray-interlock (t-shirt jersey): 0.187 kg/m^2; softest bending measured but one.
      make("jersey", 0.187f, 8.0f, 5.0f, 2.0f, 0.66f, 1.2e-5f, 0.10f, 0.35f, 0.0006f),
      // Wang 2011 ivory-rib-knit: 0.276 kg/m^2.
      make("rib_knit", 0.276f, 8.0f, 4.0f, 2.0f, 1.38f, 3.0e-5f, 0.10f, 0.35f, 0.0009f),
      // Penava 2014 wool: 0.2348 kg/m^2, 0.568 mm.
      make("wool", 0.2348f, 18.0f, 15.0f, 4.0f, 1.2f, 6.0e-5f, 0.05f, 0.40f, 0.000568f),
      // Wang 2011 white-dots-on-blk (polyester tablecloth): 0.128 kg/m^2.
      make("polyester", 0.128f, 22.0f, 18.0f, 5.0f, 0.93f, 1.8e-5f, 0.04f, 0.25f, 0.00025f),
  };
  return table;
}

}  // namespace

std::span<const Fabric> fabric_presets() { return presets(); }

std::string fabric_preset_names() {
  std::string names;
  for (const Fabric& f : presets()) names += (names.empty() ? "" : ", ") + f.name;
  return names;
}

const Fabric* find_fabric(std::string_view name) {
  for (const Fabric& f : presets())
    if (f.name == name) return &f;
  return nullptr;
}

const Fabric& fabric_or_throw(std::string_view name) {
  if (const Fabric* f = find_fabric(name)) return *f;
  throw InputError("--fabric", "unknown fabric '" + std::string(name) + "' (known: " + fabric_preset_names() + ")");
}

void validate_fabric(const Fabric& f, const std::string& source) {
  // Each parameter with the range in which the model means something.
  struct Check {
    const char* name;
    float value, lo, hi;
  };
  const Check checks[] = {
      {"areal_density", f.areal_density, 1e-3f, 10.0f},   {"stretch_warp", f.stretch_warp, 1e-3f, 1e7f},
      {"stretch_weft", f.stretch_weft, 1e-3f, 1e7f},      {"shear", f.shear, 0.0f, 1e7f},
      {"bend", f.bend, 0.0f, 1e7f},                       {"damping_ratio", f.damping_ratio, 0.0f, 1.0f},
      {"bending_rigidity", f.bending_rigidity, 0.0f, 1.0f},
      {"air_damping", f.air_damping, 0.0f, 1e3f},         {"air_drag", f.air_drag, 0.0f, 1e3f},
      {"friction", f.friction, 0.0f, 10.0f},              {"restitution", f.restitution, 0.0f, 1.0f},
      {"strain_threshold", f.strain_threshold, 1e-4f, 1.0f}, {"thickness", f.thickness, 0.0f, 0.1f},
      {"collision_thickness", f.collision_thickness, 0.0f, 0.1f},
  };
  for (const Check& c : checks)
    if (!std::isfinite(c.value) || c.value < c.lo || c.value > c.hi)
      throw InputError(source, std::string("fabric '") + f.name + "': " + c.name + " = " + std::to_string(c.value) +
                                   " is outside [" + std::to_string(c.lo) + ", " + std::to_string(c.hi) + "]");
}

}  // namespace drape
