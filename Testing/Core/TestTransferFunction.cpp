// Transfer-function table, opacity correction and the classification range query.
#include "spaceskip/TransferFunction.h"
#include "spaceskip/TransferFunctionIO.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace spaceskip;

TEST(TransferFunction, PiecewiseLinearTable) {
  auto tf = TransferFunction::fromPoints({{0, 0, 0, 0, 0}, {10, 1, 0.5f, 0, 1}}, 0, 10, 11);
  ASSERT_EQ(tf.table.size(), 11u);
  EXPECT_FLOAT_EQ(tf.table[0].w, 0.f);
  EXPECT_FLOAT_EQ(tf.table[5].w, 0.5f);
  EXPECT_FLOAT_EQ(tf.table[5].y, 0.25f);
  EXPECT_FLOAT_EQ(tf.table[10].x, 1.f);
}

TEST(TransferFunction, OpacityCorrection) {
  // Two half steps must accumulate the same opacity as one full step.
  float a = 0.6f;
  float half = correctOpacity(a, 0.5f, 1.f);
  EXPECT_NEAR(1.f - (1.f - half) * (1.f - half), a, 1e-6);
  EXPECT_FLOAT_EQ(correctOpacity(a, 1.f, 1.f), a);
  EXPECT_FLOAT_EQ(correctOpacity(0.f, 0.3f, 1.f), 0.f);
  EXPECT_FLOAT_EQ(correctOpacity(1.f, 0.3f, 1.f), 1.f);
  // Unit distance scales the exponent.
  EXPECT_NEAR(correctOpacity(a, 2.f, 2.f), a, 1e-6);
  EXPECT_NEAR(correctOpacity(a, 2.f, 1.f), 1 - 0.4f * 0.4f, 1e-6);
}

TEST(TransferFunction, LookupInterpolatesAndHandlesNaN) {
  auto tf = TransferFunction::fromPoints({{0, 0, 0, 0, 0}, {1, 1, 1, 1, 1}}, 0, 1, 2);
  TransferFunctionView v{tf.table.data(), 2, 0.f, 1.f};
  EXPECT_FLOAT_EQ(lookup(v, 0.25f).w, 0.25f);
  EXPECT_FLOAT_EQ(lookup(v, -5.f).w, 0.f);   // clamped below
  EXPECT_FLOAT_EQ(lookup(v, 7.f).w, 1.f);    // clamped above
  EXPECT_FLOAT_EQ(lookup(v, INFINITY).w, 1.f);
  EXPECT_FLOAT_EQ(lookup(v, NAN).w, 0.f);    // NaN is transparent
}

TEST(TransferFunction, RangeMaxSeesOneEntrySpike) {
  auto tf = TransferFunction::preset("spike", 0, 1023, 1024);
  OpacityRangeMax q(tf);
  EXPECT_GT(q.query(500, 524), 0.f);     // range straddles the spike at 512
  EXPECT_GT(q.query(512, 512), 0.f);
  EXPECT_EQ(q.query(0, 400), 0.f);
  EXPECT_EQ(q.query(600, 1023), 0.f);
  EXPECT_EQ(q.query(NAN, NAN), 0.f);
  EXPECT_EQ(q.query(5, 1), 0.f);         // empty range
}

TEST(TransferFunction, PresetsAndErrors) {
  EXPECT_THROW(TransferFunction::preset("nope", 0, 1), std::invalid_argument);
  EXPECT_THROW(loadTransferFunction("/nonexistent.tf", 0, 1), std::runtime_error);
  // Constant data: a degenerate range still yields a usable table.
  auto tf = TransferFunction::preset("ramp", 5, 5);
  EXPECT_GT(tf.rangeMax, tf.rangeMin);
}

TEST(TransferFunction, ColourAndOpacityComparison) {
  auto a = TransferFunction::preset("ramp", 0, 255);
  auto b = a;
  b.table[3].x += 0.1f;
  EXPECT_TRUE(a.sameOpacity(b));
  EXPECT_FALSE(a.sameColor(b));
  b = a;
  b.table[3].w += 0.1f;
  EXPECT_FALSE(a.sameOpacity(b));
  EXPECT_TRUE(a.sameColor(b));
}
