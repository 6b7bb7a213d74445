// materials/tensor.h: the flattening of 3x3 tensors into 9-vectors (column-major, index i + 3 J)
// that every tangent A = dP/dF of the constitutive kernels is written in.
#include "materials/tensor.h"

#include <gtest/gtest.h>

namespace pneufem {
namespace {

Mat3 sample() {
  Mat3 A;
  A << 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0;
  return A;
}

TEST(Tensor, FlatIsColumnMajor) {
  const Mat3 A = sample();
  const Vec9 a = flatten(A);
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J) EXPECT_EQ(a(flat(i, J)), A(i, J)) << i << J;
  EXPECT_EQ(flat(1, 0), 1);  // down a column first
  EXPECT_EQ(flat(0, 1), 3);
  EXPECT_EQ(unflatten(a), A);  // a round trip, bit for bit
}

TEST(Tensor, ATangentActsOnFlattenedTensors) {
  // P(F) = M F has dP_iJ/dF_kL = M_ik delta_JL; written as A(flat(i,J), flat(k,L)) it must map
  // flatten(F) to flatten(M F) - the convention the laws' tangents are assembled in.
  const Mat3 M = sample();
  Mat9 A = Mat9::Zero();
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J)
      for (int k = 0; k < 3; ++k) A(flat(i, J), flat(k, J)) = M(i, k);
  Mat3 F;
  F << 1.1, 0.2, -0.3, 0.0, 0.9, 0.4, 0.5, -0.1, 1.2;
  const Vec9 got = A * flatten(F);
  const Vec9 want = flatten(M * F);
  for (int r = 0; r < 9; ++r) EXPECT_NEAR(got(r), want(r), 1e-14) << r;  // sums of 3 products of O(10)
}

}  // namespace
}  // namespace pneufem
