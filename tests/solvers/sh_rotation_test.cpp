// Tests of SH projection and rotation: orthogonal blocks, rotation equals
// re-projection of the rotated function, composition, zonal-harmonic identity.
#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "solvers/sh_rotation.h"
#include "test_common.h"

using namespace bf;

namespace {
Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  Eigen::Quaterniond q(N(rng), N(rng), N(rng), N(rng));
  return q.normalized().toRotationMatrix();
}
}  // namespace

TEST_CASE("sh rotation: blocks are orthogonal per band") {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 3; ++trial) {
    const ShRotation rot = sh_rotation(20, random_rotation(rng));
    double worst = 0.0;
    for (int l = 0; l <= 20; ++l) {
      const Eigen::MatrixXd& D = rot.blocks[l];
      worst = std::max(worst, (D * D.transpose() - Eigen::MatrixXd::Identity(2 * l + 1, 2 * l + 1))
                                  .cwiseAbs()
                                  .maxCoeff());
    }
    INFO("max |D D^T - I| = " << worst);
    CHECK(worst < 1e-12);
  }
}

TEST_CASE("sh rotation: rotating coefficients equals re-projecting the rotated function") {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> N(0.0, 1.0);
  const int F = 12;
  const ShBasis basis(F);
  Eigen::VectorXd c(basis.size());
  for (int i = 0; i < c.size(); ++i) c[i] = N(rng);
  const SphereRule exact = sphere_rule(F + 1, 2 * F + 1);
  // Projection of a band-limited function returns its coefficients.
  const auto f = [&](const Eigen::Vector3d& s) { return basis.eval(s).dot(c); };
  CHECK((sh_project(F, f, exact) - c).cwiseAbs().maxCoeff() < 1e-12);
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::Matrix3d R = random_rotation(rng);
    const auto g = [&](const Eigen::Vector3d& s) { return f(R.transpose() * s); };
    const Eigen::VectorXd rotated = sh_rotate(R, c);
    const Eigen::VectorXd reprojected = sh_project(F, g, exact);
    INFO("max difference = " << (rotated - reprojected).cwiseAbs().maxCoeff());
    CHECK((rotated - reprojected).cwiseAbs().maxCoeff() < 1e-12);
    // Pointwise: sum c'_i y_i(s) = f(R^T s).
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector3d s = Eigen::Vector3d(N(rng), N(rng), N(rng)).normalized();
      CHECK(std::abs(basis.eval(s).dot(rotated) - g(s)) < 1e-11);
    }
  }
}

TEST_CASE("sh rotation: composition D(R1 R2) = D(R1) D(R2) and z-rotation pairs") {
  std::mt19937_64 rng(13);
  const Eigen::Matrix3d R1 = random_rotation(rng), R2 = random_rotation(rng);
  const int F = 8;
  const Eigen::MatrixXd D12 = sh_rotation(F, R1 * R2).dense();
  const Eigen::MatrixXd D1D2 = sh_rotation(F, R1).dense() * sh_rotation(F, R2).dense();
  CHECK((D12 - D1D2).cwiseAbs().maxCoeff() < 1e-12);
  // Rotation about z by alpha mixes only (m, -m) pairs: y_lm(R^T s) with
  // phi -> phi - alpha gives c'_{l,m} = cos(m a) c_{l,m} - sin(m a) c_{l,-m}.
  const double a = 0.7;
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const ShRotation rz = sh_rotation(F, Rz);
  for (int l = 1; l <= F; ++l)
    for (int m = 1; m <= l; ++m) {
      const Eigen::MatrixXd& D = rz.blocks[l];
      CHECK(std::abs(D(l + m, l + m) - std::cos(m * a)) < 1e-13);
      CHECK(std::abs(D(l + m, l - m) + std::sin(m * a)) < 1e-13);
      CHECK(std::abs(D(l - m, l + m) - std::sin(m * a)) < 1e-13);
    }
}

TEST_CASE("sh rotation: zonal-harmonic identity g_lm = sqrt(4pi/(2l+1)) f_l y_lm(C)") {
  // A band-limited zonal function h(z) = 0.2 + z + 0.5 z^3 - z^6, order 6,
  // centred at C (notes §1.3.7, derived with the addition theorem).
  const int F = 6;
  const auto h = [](double z) { return 0.2 + z + 0.5 * z * z * z - std::pow(z, 6); };
  const SphereRule exact = sphere_rule(F + 1, 2 * F + 1);
  const Eigen::VectorXd zonal = sh_project(F, [&](const Eigen::Vector3d& s) { return h(s.z()); }, exact);
  const Eigen::Vector3d C = Eigen::Vector3d(0.3, -0.8, 0.52).normalized();
  const Eigen::VectorXd direct = sh_project(F, [&](const Eigen::Vector3d& s) { return h(C.dot(s)); }, exact);
  const Eigen::VectorXd yC = sh_eval(F, C);
  // A rotation taking +z to C.
  const Eigen::Matrix3d R =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), C).toRotationMatrix();
  const Eigen::VectorXd rotated = sh_rotate(R, zonal);
  for (int l = 0; l <= F; ++l)
    for (int m = -l; m <= l; ++m) {
      if (m != 0) CHECK(std::abs(zonal[sh_index(l, m)]) < 1e-13);
      const double expect =
          std::sqrt(4 * M_PI / (2 * l + 1)) * zonal[sh_index(l, 0)] * yC[sh_index(l, m)];
      CHECK(std::abs(direct[sh_index(l, m)] - expect) < 1e-12);
      CHECK(std::abs(rotated[sh_index(l, m)] - expect) < 1e-12);
    }
}

TEST_CASE("sh rotation: invalid input throws") {
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(0, 0) = 2.0;
  REQUIRE_THROWS_WITH(sh_rotation(3, S), Catch::Contains("not orthogonal"));
  REQUIRE_THROWS_WITH(sh_rotation(3, -Eigen::Matrix3d::Identity()), Catch::Contains("reflection"));
  REQUIRE_THROWS_WITH(sh_rotate(Eigen::Matrix3d::Identity(), Eigen::VectorXd::Zero(5)),
                      Catch::Contains("not a square"));
  REQUIRE_THROWS_WITH(sh_rotation(2, Eigen::Matrix3d::Identity()).apply(Eigen::VectorXd::Zero(4)),
                      Catch::Contains("expected 9 coefficients"));
}

TEST_CASE("sh fast rotator: z rotation and zyz rotation equal the projected rotation matrices") {
  std::mt19937_64 rng(21);
  std::normal_distribution<double> N(0.0, 1.0);
  const int F = 9;
  Eigen::VectorXd c(sh_count(F));
  for (int i = 0; i < c.size(); ++i) c[i] = N(rng);
  // z only.
  {
    const double a = 0.7;
    Eigen::VectorXd z = c;
    sh_rotate_z(F, a, z.data());
    const Eigen::Matrix3d Rz = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    CHECK((z - sh_rotation(F, Rz).apply(c)).cwiseAbs().maxCoeff() < 1e-12);
  }
  const ShFastRotator fast(F);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Matrix3d R = random_rotation(rng);
    Eigen::VectorXd r = c;
    fast.rotate(R, r.data());
    const double err = (r - sh_rotation(F, R).apply(c)).cwiseAbs().maxCoeff();
    INFO("trial " << trial << ": max |fast - projected| = " << err);
    CHECK(err < 1e-11);
  }
  // Gimbal cases: b = 0 and b = pi.
  for (const Eigen::Matrix3d& R :
       {Eigen::Matrix3d(Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitZ())),
        Eigen::Matrix3d(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY())),
        Eigen::Matrix3d(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()))}) {
    const Eigen::Vector3d e = ShFastRotator::euler_zyz(R);
    const Eigen::Matrix3d back = (Eigen::AngleAxisd(e[0], Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(e[1], Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(e[2], Eigen::Vector3d::UnitZ())).toRotationMatrix();
    CHECK((back - R).cwiseAbs().maxCoeff() < 1e-12);
    Eigen::VectorXd r = c;
    fast.rotate(R, r.data());
    CHECK((r - sh_rotation(F, R).apply(c)).cwiseAbs().maxCoeff() < 1e-11);
  }
  CHECK_THROWS_WITH(ShFastRotator::euler_zyz(Eigen::Matrix3d::Identity() * 2.0),
                    Catch::Matchers::Contains("not a rotation"));
}
