// Tests of quaternion-pair 4D rotations: orthonormality, composition, power,
// periodicity of search lines, sign equivalence, guesses.
#include <Eigen/LU>
#include <random>

#include "search/rotation4.h"
#include "test_common.h"

using namespace bf;

TEST_CASE("rotation4: matrices are orthonormal with det +1") {
  std::mt19937_64 rng(1);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Matrix4d M = Rotation4::random(rng).matrix();
    CHECK((M * M.transpose() - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff() < 1e-12);
    CHECK(std::abs(M.determinant() - 1.0) < 1e-12);
  }
}

TEST_CASE("rotation4: composition and inverse agree with matrix products") {
  std::mt19937_64 rng(2);
  for (int k = 0; k < 100; ++k) {
    const Rotation4 a = Rotation4::random(rng), b = Rotation4::random(rng);
    CHECK((a.compose(b).matrix() - a.matrix() * b.matrix()).cwiseAbs().maxCoeff() < 1e-12);
    CHECK((a.inverse().matrix() - a.matrix().transpose()).cwiseAbs().maxCoeff() < 1e-12);
    CHECK(a.compose(a.inverse()).equal_up_to_sign(Rotation4::identity(), 1e-12));
  }
}

TEST_CASE("rotation4: power agrees with matrix products and is continuous") {
  std::mt19937_64 rng(3);
  for (int k = 0; k < 100; ++k) {
    const Rotation4 r = Rotation4::random(rng);
    CHECK((r.pow(2).matrix() - r.matrix() * r.matrix()).cwiseAbs().maxCoeff() < 1e-11);
    CHECK((r.pow(0.5).matrix() * r.pow(0.5).matrix() - r.matrix()).cwiseAbs().maxCoeff() < 1e-11);
    CHECK((r.pow(1.3).compose(r.pow(-0.4)).matrix() - r.pow(0.9).matrix()).cwiseAbs().maxCoeff() <
          1e-11);
    CHECK(r.pow(1).equal_up_to_sign(r, 1e-12));
    CHECK(r.pow(0).equal_up_to_sign(Rotation4::identity(), 1e-15));
    // Continuity: a small step in t moves the matrix a little.
    CHECK((r.pow(0.7 + 1e-6).matrix() - r.pow(0.7).matrix()).norm() < 1e-4);
  }
}

TEST_CASE("rotation4: (S, T) and (-S, -T) are the same rotation, (S, -T) is not") {
  std::mt19937_64 rng(4);
  const Rotation4 r = Rotation4::random(rng);
  const Rotation4 neg{-r.S, -r.T}, half{r.S, -r.T};
  CHECK(r.equal_up_to_sign(neg));
  CHECK((r.matrix() - neg.matrix()).cwiseAbs().maxCoeff() < 1e-15);
  CHECK_FALSE(r.equal_up_to_sign(half));
  CHECK((r.matrix() + half.matrix()).cwiseAbs().maxCoeff() < 1e-15);
}

TEST_CASE("rotation4: search lines D^t R have period 4 pi") {
  std::mt19937_64 rng(5);
  const Rotation4 start = Rotation4::random(rng);
  // Cole's basis directions and a direction with equal angles in S and T.
  const auto basis = cole_basis_directions();
  std::vector<Rotation4> dirs(basis.begin(), basis.end());
  dirs.push_back(Rotation4{qexp(Quat(0, 0.3, 0.1, 0.0)), qexp(Quat(0, 0.0, -0.2, std::sqrt(0.06)))});
  for (size_t di = 0; di < dirs.size(); ++di) {
    const LineDirection line = LineDirection::from(dirs[di]);
    for (double t : {-1.0, 0.3, 2.0, 5.5}) {
      INFO("t = " << t);
      CHECK(line.at(start, t + 4 * M_PI).equal_up_to_sign(line.at(start, t), 1e-11));
      // Basis directions move only S (or only T): at t + 2 pi that factor is
      // negated alone, a different rotation. With equal angles in S and T both
      // are negated, which is the same rotation (period 2 pi divides 4 pi).
      if (di < 6)
        CHECK_FALSE(line.at(start, t + 2 * M_PI).equal_up_to_sign(line.at(start, t), 1e-6));
    }
    CHECK(line.at(start, 0).equal_up_to_sign(start, 1e-15));
  }
}

TEST_CASE("rotation4: the net direction passes through the sweep's end point") {
  std::mt19937_64 rng(6);
  const Rotation4 a = Rotation4::random(rng), b = Rotation4::random(rng);
  const Rotation4 D = b.compose(a.inverse());
  const LineDirection line = LineDirection::from(D);
  // Scan t for the closest approach to b.
  double best = 1e9;
  for (double t = 0; t < 4 * M_PI; t += 1e-4)
    best = std::min(best, (line.at(a, t).matrix() - b.matrix()).norm());
  CHECK(best < 1e-3);
}

TEST_CASE("rotation4: projections are the rotated first two basis vectors") {
  std::mt19937_64 rng(7);
  const Rotation4 r = Rotation4::random(rng);
  const Projection p = r.projection(Parameterization::WiWo, 16);
  CHECK_NOTHROW(p.validate());
  CHECK((p.P.row(0).transpose() - r.matrix().col(0)).norm() < 1e-14);
  CHECK((p.P.row(1).transpose() - r.matrix().col(1)).norm() < 1e-14);
  CHECK(Rotation4::identity().projection(Parameterization::WiWo, 8).P.isApprox(
      projection_first_pair(Parameterization::WiWo, 8).P));
}

TEST_CASE("rotation4: guesses wi, wo, wi+wo give the thesis's projections") {
  const Mat24 wo = guess_rotation("wo").projection(Parameterization::WiWo, 8).P;
  CHECK((wo - projection_second_pair(Parameterization::WiWo, 8).P).cwiseAbs().maxCoeff() < 1e-12);
  const Mat24 sum = guess_rotation("wi+wo").projection(Parameterization::WiWo, 8).P;
  Mat24 expect;
  expect << 1, 0, 1, 0, 0, 1, 0, 1;
  expect /= std::sqrt(2.0);
  CHECK((sum - expect).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(guess_rotation("wi").equal_up_to_sign(Rotation4::identity()));
  CHECK_THROWS_WITH(guess_rotation("h"), Catch::Contains("expected \"wi\", \"wo\" or \"wi+wo\""));
  // [w, x, y, z] layout: the guess's S and T are unit quaternions.
  const Rotation4 g = guess_rotation("wi+wo");
  CHECK(std::abs(g.S.norm() - 1) < 1e-12);
  CHECK(std::abs(g.T.norm() - 1) < 1e-12);
}
