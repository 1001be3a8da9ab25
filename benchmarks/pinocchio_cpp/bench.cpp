// Pinocchio's per-call C++ time for rnea, computeRNEADerivatives, computeABADerivatives
// and computeMinverse: the reference figures of benchmarks/bench_derivatives.py, which
// builds and runs this through benchmarks/pinocchio_cpp/run.py (see there).
//
//   bench MODEL_TXT NUMBER REPEAT
//
// MODEL_TXT describes a Pinocchio model that run.py parsed from a URDF with Pinocchio's own
// parser (so the C++ side needs no URDF library, and this file is compiled header-only with
// -march=native, the fastest Pinocchio can be here): a first line "gravity gx gy gz", then
// one line per joint in Pinocchio's order,
//   parent type ax ay az  R00 R01 R02 R10 R11 R12 R20 R21 R22  px py pz  m cx cy cz Ixx Ixy Iyy Ixz Iyz Izz
// (type: RX RY RZ RU PX PY PZ PU, U = unaligned about/along a; the joint placement in its
// parent; the body's inertia in the joint frame, about the centre of mass c).
// Each figure is the median over REPEAT runs of NUMBER calls, the calls cycling through 64
// random states (fixed seed). Prints one JSON object: nv, per-call seconds of each
// algorithm, and the first state with Pinocchio's tau there (run.py compares it with
// Pinocchio's Python bindings on the same model).
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

using Clock = std::chrono::steady_clock;

template <class F>
double median_per_call(F&& call, int number, int repeat) {
  std::vector<double> times;
  for (int r = 0; r < repeat; ++r) {
    auto t0 = Clock::now();
    for (int k = 0; k < number; ++k) call(k);
    std::chrono::duration<double> dt = Clock::now() - t0;
    times.push_back(dt.count() / number);
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

// The model described in `path` (format above); throws on a malformed line.
pinocchio::Model read_model(const char* path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(std::string("cannot read ") + path);
  pinocchio::Model model;
  std::string word;
  double g[3];
  if (!(in >> word >> g[0] >> g[1] >> g[2]) || word != "gravity") throw std::runtime_error("no gravity line");
  model.gravity.linear(Eigen::Vector3d(g[0], g[1], g[2]));
  std::string line;
  int k = 0;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream ls(line);
    int parent;
    std::string type;
    double a[3], r[9], p[3], m, c[3], I[6];
    ls >> parent >> type;
    for (double& x : a) ls >> x;
    for (double& x : r) ls >> x;
    for (double& x : p) ls >> x;
    ls >> m;
    for (double& x : c) ls >> x;
    for (double& x : I) ls >> x;
    if (!ls) throw std::runtime_error("malformed joint line: " + line);
    Eigen::Matrix3d R;
    R << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
    const pinocchio::SE3 placement(R, Eigen::Vector3d(p[0], p[1], p[2]));
    const Eigen::Vector3d axis(a[0], a[1], a[2]);
    const std::string name = "joint" + std::to_string(++k);
    pinocchio::JointIndex id;
    if (type == "RX") id = model.addJoint(parent, pinocchio::JointModelRX(), placement, name);
    else if (type == "RY") id = model.addJoint(parent, pinocchio::JointModelRY(), placement, name);
    else if (type == "RZ") id = model.addJoint(parent, pinocchio::JointModelRZ(), placement, name);
    else if (type == "RU") id = model.addJoint(parent, pinocchio::JointModelRevoluteUnaligned(axis), placement, name);
    else if (type == "PX") id = model.addJoint(parent, pinocchio::JointModelPX(), placement, name);
    else if (type == "PY") id = model.addJoint(parent, pinocchio::JointModelPY(), placement, name);
    else if (type == "PZ") id = model.addJoint(parent, pinocchio::JointModelPZ(), placement, name);
    else if (type == "PU") id = model.addJoint(parent, pinocchio::JointModelPrismaticUnaligned(axis), placement, name);
    else throw std::runtime_error("unknown joint type " + type);
    Eigen::Matrix3d Ic;
    Ic << I[0], I[1], I[3], I[1], I[2], I[4], I[3], I[4], I[5];
    model.appendBodyToJoint(id, pinocchio::Inertia(m, Eigen::Vector3d(c[0], c[1], c[2]), Ic), pinocchio::SE3::Identity());
  }
  return model;
}

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s MODEL_TXT NUMBER REPEAT\n", argv[0]);
    return 2;
  }
  const int number = std::atoi(argv[2]), repeat = std::atoi(argv[3]);
  pinocchio::Model model;
  try {
    model = read_model(argv[1]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  pinocchio::Data data(model);

  const int S = 64;  // states cycled through, so no call sees the previous call's inputs
  std::mt19937 gen(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::VectorXd> q(S), v(S), a(S), tau(S);
  for (int s = 0; s < S; ++s) {
    q[s] = pinocchio::neutral(model);
    v[s] = Eigen::VectorXd(model.nv);
    a[s] = Eigen::VectorXd(model.nv);
    for (int i = 0; i < model.nq; ++i) q[s][i] += 3.0 * u(gen);  // nq = nv: revolute / prismatic
    for (int i = 0; i < model.nv; ++i) v[s][i] = u(gen), a[s][i] = u(gen);
    tau[s] = pinocchio::rnea(model, data, q[s], v[s], a[s]);
  }
  Eigen::VectorXd tau0 = pinocchio::rnea(model, data, q[0], v[0], a[0]);
  double sink = 0.0;  // results read, so no call is optimised away

  double t_rnea = median_per_call([&](int k) { sink += pinocchio::rnea(model, data, q[k % S], v[k % S], a[k % S])[0]; },
                                  number, repeat);
  double t_rnea_d = median_per_call([&](int k) {
    pinocchio::computeRNEADerivatives(model, data, q[k % S], v[k % S], a[k % S]);
    sink += data.dtau_dq(0, 0);
  }, number, repeat);
  double t_aba_d = median_per_call([&](int k) {
    pinocchio::computeABADerivatives(model, data, q[k % S], v[k % S], tau[k % S]);
    sink += data.ddq_dq(0, 0);
  }, number, repeat);
  double t_minv = median_per_call([&](int k) {
    pinocchio::computeMinverse(model, data, q[k % S]);
    sink += data.Minv(0, 0);
  }, number, repeat);

  std::printf("{\"nv\": %d, \"number\": %d, \"repeat\": %d, \"rnea\": %.6e, \"rnea_derivatives\": %.6e, "
              "\"aba_derivatives\": %.6e, \"minverse\": %.6e, \"sink\": %.17g, \"q0\": [",
              model.nv, number, repeat, t_rnea, t_rnea_d, t_aba_d, t_minv, sink);
  for (int i = 0; i < model.nq; ++i) std::printf("%s%.17g", i ? ", " : "", q[0][i]);
  std::printf("], \"v0\": [");
  for (int i = 0; i < model.nv; ++i) std::printf("%s%.17g", i ? ", " : "", v[0][i]);
  std::printf("], \"a0\": [");
  for (int i = 0; i < model.nv; ++i) std::printf("%s%.17g", i ? ", " : "", a[0][i]);
  std::printf("], \"tau0\": [");
  for (int i = 0; i < model.nv; ++i) std::printf("%s%.17g", i ? ", " : "", tau0[i]);
  std::printf("]}\n");
  return 0;
}
