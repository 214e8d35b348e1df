// drape next to Bullet's soft body (Debian libbullet 3.24, btSoftBody, position based) on the same
// scene, in one run: ../shared/peers' `sphere` scenario (peers/README.md, bullet_drape.cpp): a 1 m
// cloth of n x n vertices 0.1 m above a sphere of radius 0.3 m, 2.0 s of simulated time, 0.2 kg/m^2,
// friction 0.3, a 10 mm contact margin (drape: collision thickness), air drag 1/s, no self collision.
// Bullet steps at dt = 1/120 s with 10 position iterations (the peers' setting); drape's explicit
// step at its eq. 4 bound with velocity modification at 5 %, its implicit one (the default solver)
// at 1/30 s with the strain limit at 5 % inside the solve. Reported per engine: ms per step, wall
// seconds for the 2 s, final max strain; then the ratios (per step and per simulated second).
//   build-sim/bench_peer_bullet --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <btBulletDynamicsCommon.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "drape/cloth_scene.hpp"
#include "peer_scene.hpp"

namespace {

using peer::kAirDrag;
using peer::kDensity;
using peer::kFriction;
using peer::kMargin;
using peer::kSimulatedSeconds;

struct Result {
  double wall_seconds = 0;
  double steps = 0;
  double max_strain = 0;
  double ms_per_step() const { return 1e3 * wall_seconds / steps; }
};

// Bullet, as ../shared/peers/bullet_drape.cpp --solver pbd sets it up (z up there).
Result run_bullet(int n) {
  const double radius = 0.3, z0 = radius + 0.1, h = 1.0 / (n - 1), dt = 1.0 / 120.0;
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btSoftRigidDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
  const btVector3 g(0, 0, -9.81f);
  world.setGravity(g);
  btSoftBodyWorldInfo& info = world.getWorldInfo();
  info.m_gravity = g;
  info.air_density = 0;
  info.water_density = 0;
  info.m_sparsesdf.setDefaultVoxelsz(0.05f);
  info.m_sparsesdf.Reset();

  btSphereShape sphere(static_cast<btScalar>(radius));
  btDefaultMotionState motion(btTransform::getIdentity());
  btRigidBody::btRigidBodyConstructionInfo body_info(0, &motion, &sphere, btVector3(0, 0, 0));
  btRigidBody body(body_info);
  body.setFriction(static_cast<btScalar>(kFriction));
  world.addRigidBody(&body);

  const auto z = static_cast<btScalar>(z0);
  btSoftBody* cloth = btSoftBodyHelpers::CreatePatch(info, btVector3(-0.5f, -0.5f, z), btVector3(0.5f, -0.5f, z),
                                                     btVector3(-0.5f, 0.5f, z), btVector3(0.5f, 0.5f, z), n, n, 0, false);
  btSoftBody::Material* shear = cloth->appendMaterial();
  shear->m_kLST = 1;
  btSoftBody::Material* bend = cloth->appendMaterial();
  bend->m_kLST = 0.1f;
  for (int iy = 0; iy + 1 < n; ++iy)
    for (int ix = 0; ix + 1 < n; ++ix) {
      const int i = iy * n + ix;
      cloth->appendLink(i, i + n + 1, shear);
      cloth->appendLink(i + 1, i + n, shear);
    }
  cloth->generateBendingConstraints(2, bend);
  cloth->getCollisionShape()->setMargin(static_cast<btScalar>(kMargin));
  cloth->setTotalMass(static_cast<btScalar>(kDensity), false);
  cloth->m_cfg.kDF = 1;
  cloth->m_cfg.kCHR = 1;
  cloth->m_cfg.kKHR = 1;
  cloth->m_cfg.kSRHR_CL = 1;
  cloth->m_cfg.collisions = btSoftBody::fCollision::SDF_RS;
  cloth->m_cfg.piterations = 10;
  cloth->m_cfg.viterations = 0;
  cloth->m_cfg.diterations = 0;
  cloth->m_cfg.kDP = static_cast<btScalar>(1 - std::exp(-kAirDrag * dt));
  world.addSoftBody(cloth);
  cloth->setActivationState(DISABLE_DEACTIVATION);

  const int steps = static_cast<int>(std::lround(kSimulatedSeconds / dt));
  const auto start = std::chrono::steady_clock::now();
  for (int s = 0; s < steps; ++s) world.stepSimulation(static_cast<btScalar>(dt), 0, static_cast<btScalar>(dt));
  Result r;
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.steps = steps;
  // Grid-edge strain, as the peers measure it.
  for (int iy = 0; iy < n; ++iy)
    for (int ix = 0; ix < n; ++ix) {
      const int i = iy * n + ix;
      for (int j : {ix + 1 < n ? i + 1 : -1, iy + 1 < n ? i + n : -1})
        if (j >= 0)
          r.max_strain = std::max(r.max_strain, (cloth->m_nodes[i].m_x - cloth->m_nodes[j].m_x).length() / h - 1.0);
    }
  world.removeSoftBody(cloth);
  delete cloth;
  world.removeRigidBody(&body);
  return r;
}

// drape on the same scene (y up): cotton stiffness, the peers' mass, friction, margin and drag.
Result run_drape(int n, drape::Solver solver = drape::Solver::Explicit) {
  drape::ClothScene scene = drape::make_cloth_scene(peer::scene_options(drape::SceneObstacle::Sphere, n, solver));
  const auto start = std::chrono::steady_clock::now();
  // The end of the 2 s within half a step (the implicit step's 1/30 s does not divide it exactly
  // in floating point).
  const double end = kSimulatedSeconds - 0.5 * scene.time_step();
  double steps = 0;
  while (scene.state.time < end) {
    const drape::StepStatus status =
        scene.implicit ? scene.implicit->step(scene.state, scene.colliders, scene.implicit_settings)
                       : drape::step(scene.model, scene.state, scene.colliders, scene.settings, scene.scratch);
    if (status != drape::StepStatus::Ok) break;
    ++steps;
  }
  Result r;
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.steps = steps;
  r.max_strain = drape::scene_quality(scene).strain.max;
  return r;
}

void report(benchmark::State& state, const Result& r, int n) {
  state.SetIterationTime(r.wall_seconds);
  state.counters["vertices"] = n * n;
  state.counters["steps"] = r.steps;
  state.counters["ms_per_step"] = r.ms_per_step();
  state.counters["wall_s_for_2s"] = r.wall_seconds;
  state.counters["max_strain"] = r.max_strain;
  state.counters["vertex_iterations_per_s"] = n * n * r.steps / r.wall_seconds;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  std::map<int, Result> bullet, drape1, drape2, implicit2;
  for (int n : {32, 64, 128}) {
    benchmark::RegisterBenchmark(("bullet_pbd/n:" + std::to_string(n)).c_str(), [n, &bullet](benchmark::State& s) {
      for (auto _ : s) report(s, bullet[n] = run_bullet(n), n);
    })->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("drape/n:" + std::to_string(n) + "/threads:1").c_str(), [n, &drape1](benchmark::State& s) {
      omp_set_num_threads(1);
      for (auto _ : s) report(s, drape1[n] = run_drape(n), n);
      omp_set_num_threads(omp_get_num_procs());
    })->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("drape/n:" + std::to_string(n) + "/threads:2").c_str(), [n, &drape2](benchmark::State& s) {
      omp_set_num_threads(2);
      for (auto _ : s) report(s, drape2[n] = run_drape(n), n);
      omp_set_num_threads(omp_get_num_procs());
    })->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);
    if (n > 64) continue;  // the implicit solver at n = 128: minutes
    benchmark::RegisterBenchmark(("drape_implicit/n:" + std::to_string(n) + "/threads:2").c_str(), [n, &implicit2](benchmark::State& s) {
      omp_set_num_threads(2);
      for (auto _ : s) report(s, implicit2[n] = run_drape(n, drape::Solver::Implicit), n);
      omp_set_num_threads(omp_get_num_procs());
    })->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();

  std::printf("\n| n | Bullet ms/step | drape ms/step (1 thr / 2 thr) | per-step speed-up (2 thr) | Bullet s for 2 s | drape s for 2 s (2 thr) | "
              "per-simulated-second ratio | max strain Bullet / drape |\n|---|---|---|---|---|---|---|---|\n");
  for (const auto& [n, b] : bullet) {
    if (!drape1.count(n) || !drape2.count(n)) continue;
    const Result& d1 = drape1[n];
    const Result& d2 = drape2[n];
    std::printf("| %d | %.2f | %.3f / %.3f | %.1fx | %.2f | %.2f | %.2fx | %.3f / %.3f |\n", n, b.ms_per_step(), d1.ms_per_step(),
                d2.ms_per_step(), b.ms_per_step() / d2.ms_per_step(), b.wall_seconds, d2.wall_seconds,
                b.wall_seconds / d2.wall_seconds, b.max_strain, d2.max_strain);
  }
  std::printf("\n| n | Bullet s for 2 s (dt 1/120 s) | drape implicit s for 2 s (dt 1/30 s, 2 thr) | ms/step | "
              "per-simulated-second ratio | max strain Bullet / drape implicit |\n|---|---|---|---|---|---|\n");
  for (const auto& [n, b] : bullet) {
    if (!implicit2.count(n)) continue;
    const Result& d = implicit2[n];
    std::printf("| %d | %.2f | %.3f | %.2f | %.2fx | %.3f / %.3f |\n", n, b.wall_seconds, d.wall_seconds, d.ms_per_step(),
                b.wall_seconds / d.wall_seconds, b.max_strain, d.max_strain);
  }
  return 0;
}
