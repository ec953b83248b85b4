// Native Pinocchio side of the side-by-side timing (benches/compare/run.sh).
//
// Builds, with Pinocchio's 3D spatial algebra, the two standard models of
// mbs-core/src/benchmarks.rs (`planar_chain(5)` and `branching_tree()`), evaluates them at
// the state of mbs-core/benches/dynamics.rs, prints the values (so the script can prove the
// models are the same as ours), then times rnea, crba and aba exactly the way
// mbs-core/examples/compare_timing.rs times ours. Output, one record per line:
//
//   value <model> <quantity> <x0> <x1> ...        (%.17g, matrices row-major)
//   time  <model> <algorithm> <median_us> <min_us> <max_us> <calls_per_batch>
//
// Compiled header-only (no PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION), so every algorithm is
// instantiated here with -O3 -march=native rather than taken from the wheel's generic
// x86-64 shared library.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/config.hpp>
#include <pinocchio/multibody.hpp>

using pinocchio::Convention;
using pinocchio::Data;
using pinocchio::Inertia;
using pinocchio::JointIndex;
using pinocchio::Model;
using pinocchio::SE3;
using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {

// Same batch rule as compare_timing.rs: double the batch size until one batch lasts
// TARGET_BATCH_S (this is also the warm-up), then time BATCHES batches of that size.
constexpr int BATCHES = 30;
constexpr double TARGET_BATCH_S = 0.010;

// Tells the compiler that `p` (and everything reachable) may be read or written here, the
// equivalent of Rust's std::hint::black_box(&x): inputs are reloaded and outputs stored
// on every call.
inline void escape(const void* p) { asm volatile("" : : "g"(p) : "memory"); }

struct Timing {
  double median_us, min_us, max_us;
  long calls;
};

template <class Call>
double time_batch(Call& call, long n) {
  auto t0 = std::chrono::steady_clock::now();
  for (long i = 0; i < n; ++i) call();
  auto t1 = std::chrono::steady_clock::now();
  return std::chrono::duration<double>(t1 - t0).count();
}

template <class Call>
Timing time_per_call(Call call) {
  long n = 1;
  while (time_batch(call, n) < TARGET_BATCH_S) n *= 2;
  std::vector<double> per_call_us(BATCHES);
  for (double& t : per_call_us) t = time_batch(call, n) / double(n) * 1e6;
  std::sort(per_call_us.begin(), per_call_us.end());
  const double median = 0.5 * (per_call_us[BATCHES / 2 - 1] + per_call_us[BATCHES / 2]);
  return {median, per_call_us.front(), per_call_us.back(), n};
}

// A joint frame placed in its parent's joint frame like mbs-core's Placement::new(angle,
// x, y): rotation `angle` about z, origin (x, y, 0) in the parent frame.
SE3 placement(double angle, double x, double y) {
  return SE3(Eigen::AngleAxisd(angle, Vector3d::UnitZ()).toRotationMatrix(),
             Vector3d(x, y, 0.0));
}

// Like BodySpec::new(mass, com, izz): centre of mass (cx, cy, 0) in the joint frame, izz
// about it. The out-of-plane moments never enter planar motion; izz is used for them too.
Inertia body(double mass, double cx, double cy, double izz) {
  return Inertia(mass, Vector3d(cx, cy, 0.0), Eigen::Vector3d(izz, izz, izz).asDiagonal());
}

JointIndex add_revolute(Model& m, JointIndex parent, const SE3& x_tree, const Inertia& y,
                        const std::string& name) {
  JointIndex j = m.addJoint(parent, pinocchio::JointModelRZ(), x_tree, name);
  m.appendBodyToJoint(j, y, SE3::Identity());
  return j;
}

// A prismatic joint along the in-plane `axis` of the joint frame (normalised, as ours is).
JointIndex add_prismatic(Model& m, JointIndex parent, const SE3& x_tree, double ax, double ay,
                         const Inertia& y, const std::string& name) {
  JointIndex j =
      m.addJoint(parent, pinocchio::JointModelPrismaticUnaligned(ax, ay, 0.0), x_tree, name);
  m.appendBodyToJoint(j, y, SE3::Identity());
  return j;
}

void set_gravity(Model& m) { m.gravity = pinocchio::Motion(Vector3d(0.0, -9.81, 0.0), Vector3d::Zero()); }

// mbs_core::benchmarks::planar_chain(n).
Model planar_chain(int n) {
  Model m;
  set_gravity(m);
  JointIndex parent = 0;
  for (int i = 0; i < n; ++i) {
    const double x = i == 0 ? 0.0 : 1.0;
    parent = add_revolute(m, parent, placement(0.0, x, 0.0), body(1.0, 0.5, 0.0, 1.0 / 12.0),
                          "link" + std::to_string(i + 1));
  }
  return m;
}

// mbs_core::benchmarks::branching_tree(): joints added in the order they are declared
// there, so Pinocchio's idx_v is our coordinate order.
Model branching_tree() {
  Model m;
  set_gravity(m);
  const JointIndex trunk =
      add_revolute(m, 0, placement(0.0, 0.0, 0.0), body(2.0, 0.4, 0.02, 0.15), "trunk");
  for (int i = 0; i < 3; ++i) {
    const double fi = i;
    const JointIndex branch = add_revolute(
        m, trunk, placement(0.3 * fi - 0.3, 0.8, 0.1 * fi - 0.1),
        body(1.0 + 0.2 * fi, 0.3, -0.01 * fi, 0.05 + 0.01 * fi), "branch" + std::to_string(i));
    for (int k = 0; k < 3; ++k) {
      const double fk = k;
      const SE3 x_tree = placement(0.2 * fk - 0.2, 0.5 + 0.05 * fk, 0.03 * fk);
      const Inertia y = body(0.3 + 0.1 * fk, 0.2, 0.01, 0.01 + 0.002 * fk);
      const std::string name = "twig" + std::to_string(i) + std::to_string(k);
      if (k == 2)
        add_prismatic(m, branch, x_tree, 1.0, 0.2 * fi, y, name);
      else
        add_revolute(m, branch, x_tree, y, name);
    }
  }
  return m;
}

// `(i + 1) k` sines of amplitude 2: the deterministic spread of dynamics.rs.
VectorXd spread(int n, double k) {
  VectorXd x(n);
  for (int i = 0; i < n; ++i) x[i] = std::sin((i + 1.0) * k) * 2.0;
  return x;
}

struct State {
  VectorXd q, v, a, tau_check;
};

// `fn state` of mbs-core/benches/dynamics.rs; tau_check is the torque at which ABA's
// result is compared (independent of either engine's RNEA, so a model mismatch shows).
State state(int nv) {
  State s;
  if (nv == 5) {
    s.q.resize(5);
    s.q << 1.721316619099806, -0.38403808930179695, 2.2531371815723604, 1.2400999002927886,
        -2.5498589250729733;
    s.v.resize(5);
    s.v << 1.9024894065470237, 1.0445588079614119, 1.1442572211078152, -1.4875454692978165,
        -0.19845624841773146;
    s.a.resize(5);
    s.a << -1.2920197576741876, 4.267649888486018, 1.4386512008066452, 3.227616132708299,
        -0.5658580117266885;
  } else {
    s.q = spread(nv, 0.7);
    s.v = spread(nv, 1.3);
    s.a = spread(nv, 2.9);
  }
  s.tau_check = spread(nv, 4.1);
  return s;
}

void print_values(const char* model, const char* quantity, const double* x, long n) {
  std::printf("value %s %s", model, quantity);
  for (long i = 0; i < n; ++i) std::printf(" %.17g", x[i]);
  std::printf("\n");
}

void print_timing(const char* model, const char* algorithm, const Timing& t) {
  std::printf("time %s %s %.5f %.5f %.5f %ld\n", model, algorithm, t.median_us, t.min_us,
              t.max_us, t.calls);
  std::fflush(stdout);
}

void run(const char* name, const Model& model) {
  Data data(model);
  const State s = state(model.nv);
  const long nv = model.nv;

  print_values(name, "q", s.q.data(), nv);
  print_values(name, "v", s.v.data(), nv);
  print_values(name, "a", s.a.data(), nv);
  print_values(name, "tau_check", s.tau_check.data(), nv);
  const VectorXd tau = pinocchio::rnea(model, data, s.q, s.v, s.a);
  print_values(name, "rnea_tau", tau.data(), nv);
  pinocchio::crba(model, data, s.q);
  // crba fills the upper triangle; mirror it for the comparison only.
  Eigen::MatrixXd mass = data.M;
  mass.triangularView<Eigen::StrictlyLower>() = mass.transpose();
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows = mass;
  print_values(name, "mass_matrix", rows.data(), nv * nv);
  const VectorXd qdd = pinocchio::aba(model, data, s.q, s.v, s.tau_check);
  print_values(name, "aba_qdd", qdd.data(), nv);

  const VectorXd &q = s.q, &v = s.v, &a = s.a;
  print_timing(name, "rnea", time_per_call([&] {
                 escape(q.data());
                 escape(v.data());
                 escape(a.data());
                 escape(pinocchio::rnea(model, data, q, v, a).data());
               }));
  print_timing(name, "crba", time_per_call([&] {
                 escape(q.data());
                 escape(pinocchio::crba(model, data, q).data());
               }));
  // ABA at RNEA's torque, as dynamics.rs times it (Pinocchio's default, local convention).
  print_timing(name, "aba", time_per_call([&] {
                 escape(q.data());
                 escape(v.data());
                 escape(tau.data());
                 escape(pinocchio::aba(model, data, q, v, tau).data());
               }));
  // The world-convention variants, for reference (not in the ratio).
  print_timing(name, "crba_world", time_per_call([&] {
                 escape(q.data());
                 escape(pinocchio::crba(model, data, q, Convention::WORLD).data());
               }));
  print_timing(name, "aba_world", time_per_call([&] {
                 escape(q.data());
                 escape(v.data());
                 escape(tau.data());
                 escape(pinocchio::aba(model, data, q, v, tau, Convention::WORLD).data());
               }));
}

}  // namespace

int main() {
  std::printf("# pinocchio %s, native C++ (header-only instantiation)\n", PINOCCHIO_VERSION);
  run("planar5", planar_chain(5));
  run("tree13", branching_tree());
  return 0;
}
