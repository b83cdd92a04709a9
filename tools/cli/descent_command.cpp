// `batchcol descent`: the seed talk's example of optimising through collision detection (Part III, "Solving an
// optimization problem with collision detection derivatives"): minimise
//   C(T) = |x_a*(T) - x_a,des|^2 + |x_b*(T) - x_b,des|^2 + |x_a*(T) - x_b*(T)|^2
// over the pose T of shape b (shape a fixed) by gradient descent on SE(3), T <- exp(-step grad C) T, with the
// witness-point Jacobians from (a) central finite differences, (b) smoothed0, (c) smoothed1. The desired points
// are the witness points at a target pose. Writes case,method,iteration,cost to CSV (plot: tools/plot_descent.py).
#include "cli/atomic_output.hpp"
#include "cli/commands.hpp"

#include <batchcol/batchcol.hpp>

#include <memory>
#include <ostream>
#include <random>
#include <string>

namespace batchcol::cli {
namespace {

struct DescentSettings {
  std::string out;
  int iterations = 100, samples = 16;
  double noise = 0.05, step = 0.1, fd_step = 1e-6, max_twist = 0.05;
};

using Mat36 = Eigen::Matrix<double, 3, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

Pose twisted(const Pose& pose, const Vec6& xi) {
  const Eigen::Vector3d w = xi.tail<3>();
  const double angle = w.norm();
  const Eigen::Quaterniond q =
      angle > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / angle)) : Eigen::Quaterniond::Identity();
  return {q * pose.translation + xi.head<3>(), (q * pose.rotation).normalized()};
}

struct Problem {
  ShapeTable shapes;
  std::uint32_t a = 0, b = 0;
  Eigen::Vector3d xa_des, xb_des;
};

QueryOptions query() {
  QueryOptions q;
  q.level = QueryLevel::penetration;  // the cost's last term pulls the shapes into contact
  return q;
}

bool witness(const Problem& p, const Pose& Tb, Eigen::Vector3d& xa, Eigen::Vector3d& xb) {
  PairBatch batch;
  batch.add(p.a, Pose::identity(), p.b, Tb);
  PairResults r;
  collide(p.shapes, batch, query(), r);
  xa = r.witness_a[0];
  xb = r.witness_b[0];
  return r.status[0] == Status::converged && xa.allFinite() && xb.allFinite();
}

double cost(const Problem& p, const Eigen::Vector3d& xa, const Eigen::Vector3d& xb) {
  return (xa - p.xa_des).squaredNorm() + (xb - p.xb_des).squaredNorm() + (xa - xb).squaredNorm();
}

// dC/dxi_b from the witness Jacobians w.r.t. b's twist.
Vec6 chain(const Problem& p, const Eigen::Vector3d& xa, const Eigen::Vector3d& xb, const Mat36& Ja, const Mat36& Jb) {
  return 2.0 * (Ja.transpose() * (xa - p.xa_des) + Jb.transpose() * (xb - p.xb_des) +
                (Ja - Jb).transpose() * (xa - xb));
}

Vec6 gradient(const Problem& p, const Pose& Tb, const std::string& method, const DescentSettings& s, int iteration) {
  Eigen::Vector3d xa, xb;
  if (method == "finite_differences") {
    Vec6 g;
    for (int k = 0; k < 6; ++k) {
      Vec6 xi = Vec6::Zero();
      xi(k) = s.fd_step;
      Eigen::Vector3d pa, pb, ma, mb;
      witness(p, twisted(Tb, xi), pa, pb);
      witness(p, twisted(Tb, -xi), ma, mb);
      g(k) = (cost(p, pa, pb) - cost(p, ma, mb)) / (2.0 * s.fd_step);
    }
    return g;
  }
  PairBatch batch;
  batch.add(p.a, Pose::identity(), p.b, Tb);
  DerivativeOptions o;
  o.method = method == "smoothed0" ? DerivativeMethod::smoothed0 : DerivativeMethod::smoothed1;
  o.samples = s.samples;
  o.noise = s.noise;
  o.seed = static_cast<std::uint64_t>(iteration);  // fresh samples every iteration
  PairResults r;
  DerivativeResults d;
  differentiate(p.shapes, batch, query(), o, r, d);
  if (d.status[0] == DerivativeStatus::no_witness || d.status[0] == DerivativeStatus::singular) return Vec6::Zero();
  return chain(p, r.witness_a[0], r.witness_b[0], d.witness_a_wrt_b[0], d.witness_b_wrt_b[0]);
}

void run_case(const std::string& name, Problem& p, const Pose& start, const Pose& target, const DescentSettings& s,
              std::string& csv) {
  Eigen::Vector3d xa, xb;
  if (!witness(p, target, xa, xb)) throw InputError("descent: the target pose of case " + name + " has no witness");
  p.xa_des = xa;
  p.xb_des = xb;
  for (const std::string method : {"finite_differences", "smoothed0", "smoothed1"}) {
    Pose T = start;
    for (int it = 0; it <= s.iterations; ++it) {
      const bool ok = witness(p, T, xa, xb);
      csv += name + "," + method + "," + std::to_string(it) + "," + (ok ? std::to_string(cost(p, xa, xb)) : "") + "\n";
      if (!ok || it == s.iterations) break;
      // One step for every method, capped at max_twist (m and rad) so that a noisy gradient cannot throw the
      // shapes apart in one step: the curves then compare the gradients' directions, not their outliers.
      Vec6 xi = -s.step * gradient(p, T, method, s, it);
      if (xi.norm() > s.max_twist) xi *= s.max_twist / xi.norm();
      T = twisted(T, xi);
    }
  }
}

int run_descent(const DescentSettings& s) {
  DerivativeOptions check;
  check.samples = s.samples;
  check.noise = s.noise;
  validate(check);
  if (!(s.step > 0.0) || !(s.fd_step > 0.0) || !(s.max_twist > 0.0))
    throw InputError("--step, --fd-step and --max-twist must be > 0");
  std::string csv = "case,method,iteration,cost\n";
  const Pose start{Eigen::Vector3d(0.9, 0.3, 0.2),
                   Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d(1, 2, 3).normalized()))};
  const Pose target{Eigen::Vector3d(0.7, -0.2, 0.1),
                    Eigen::Quaterniond(Eigen::AngleAxisd(-0.4, Eigen::Vector3d(3, -1, 2).normalized()))};
  {
    Problem p;
    p.a = p.shapes.add(Shape::ellipsoid(0.2, 0.3, 0.15));
    p.b = p.shapes.add(Shape::ellipsoid(0.25, 0.1, 0.2));
    run_case("ellipsoids", p, start, target, s, csv);
  }
  {
    Problem p;
    std::mt19937_64 rng(8);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const auto hull = [&] {
      std::vector<Eigen::Vector3d> points;
      while (points.size() < 8) {
        const Eigen::Vector3d v(u(rng), u(rng), u(rng));
        if (v.norm() > 0.3) points.push_back(0.25 * v.normalized().cwiseProduct(Eigen::Vector3d(1.0, 0.8, 0.6)));
      }
      return Shape::convex(points);
    };
    p.a = p.shapes.add(hull());
    p.b = p.shapes.add(hull());
    run_case("hulls", p, start, target, s, csv);
  }
  write_file_atomically(s.out, [&](std::ostream& out) { out << csv; });
  return 0;
}

}  // namespace

Command add_descent_command(CLI::App& parent) {
  auto s = std::make_shared<DescentSettings>();
  CLI::App* app = parent.add_subcommand(
      "descent", "Gradient descent on SE(3) through collision derivatives (finite differences, smoothed0, smoothed1)");
  app->add_option("--out", s->out, "CSV file: case,method,iteration,cost")->required();
  app->add_option("--iterations", s->iterations, "Descent steps per method")->check(CLI::Range(1, 100000));
  app->add_option("--samples", s->samples, "Samples of the smoothed derivatives");
  app->add_option("--noise", s->noise, "Relative noise of the smoothed derivatives");
  app->add_option("--step", s->step, "Step size (the twist is -step * gradient)");
  app->add_option("--fd-step", s->fd_step, "Finite-difference step (m, rad)");
  app->add_option("--max-twist", s->max_twist, "Largest twist per step (m, rad)");
  return {app, [s] { return run_descent(*s); }};
}

}  // namespace batchcol::cli
