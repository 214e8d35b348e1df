#pragma once
// Fabrics: the physical parameters a cloth model is built from. Presets are documented, number by
// number, with their sources in docs/fabrics.md.
//
// Stiffnesses are membrane stiffnesses per unit width (N/m): the force per metre of cloth width
// that one unit of strain produces. A spring of rest length l that represents a strip of cloth of
// width w gets k = stiffness * w / l, so a square grid's structural springs have k = stiffness and
// the cloth's response does not depend on the mesh resolution. They are *simulation* stiffnesses,
// chosen soft enough for explicit Euler (Vassilev & Spanlang eq. 4); the inextensibility of real
// cloth comes from the strain threshold (velocity modification, sec. 3.3), as in the paper.
#include <span>
#include <string>
#include <string_view>

namespace drape {

struct Fabric {
  std::string name;
  float areal_density = 0.2f;     // kg/m^2
  float stretch_warp = 60.0f;     // N/m, along the warp (grain line, the flat pattern's v / y axis)
  float stretch_weft = 50.0f;     // N/m, along the weft (the flat pattern's u / x axis)
  float shear = 15.0f;            // N/m, shear springs (quad diagonals)
  float bend = 2.0f;              // N/m, flexion springs ([i,j]-[i+2,j]) and bending springs across edges
  // N m: bending rigidity, the moment per unit width per unit curvature (KES B), which the implicit
  // solver's bending stencils use in place of the flexion springs (ClothModel::bend_stencil).
  float bending_rigidity = 1e-5f;
  float damping_ratio = 0.1f;     // spring damping as a fraction of critical damping of one spring
  float air_damping = 0.5f;       // 1/s: viscous damping f = -gamma m v (paper sec. 2.2, C_vd = gamma m)
  float air_drag = 0.6f;          // kg/m^3: quadratic drag f = -air_drag * area * |v| v (rho_air C_d / 2)
  float friction = 0.3f;          // Coulomb coefficient against bodies and obstacles
  float restitution = 0.0f;       // C_refl of eq. 5: fraction of the normal velocity reflected
  float strain_threshold = 0.05f; // stretch threshold of velocity modification (paper: 1-10 %)
  float thickness = 0.0004f;      // m, physical thickness (for reference and rendering)
  float collision_thickness = 0.004f;  // m, distance kept between the cloth's vertices and bodies
};

// The built-in presets (cotton, denim, silk, jersey, wool, polyester, ...), in a fixed order.
std::span<const Fabric> fabric_presets();
// Their names, comma-separated, in that order (for messages and help).
std::string fabric_preset_names();

// The preset called `name` (case-sensitive), or nullptr.
const Fabric* find_fabric(std::string_view name);

// The preset called `name`; InputError("--fabric", ...) listing the known names otherwise.
const Fabric& fabric_or_throw(std::string_view name);

// Checks that every number is finite and in a meaningful range; InputError(source, ...) otherwise.
void validate_fabric(const Fabric& fabric, const std::string& source);

}  // namespace drape
