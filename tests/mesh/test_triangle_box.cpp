// The separating-axis test against hand-made cases and against an independent test
// (clipping the triangle to the box).
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "mesh_test_support.hpp"
#include "vola/mesh/triangle_box.hpp"

namespace test_triangle_box {
namespace {

using vola::Box;
using vola::mesh::Triangle;
using vola::mesh::triangle_box_overlap;

const Box kUnit{{0, 0, 0}, {1, 1, 1}};
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(TriangleBox, InsideAndFarAway) {
  EXPECT_TRUE(triangle_box_overlap({{{0.2, 0.2, 0.2}, {0.8, 0.2, 0.3}, {0.5, 0.7, 0.6}}}, kUnit));
  EXPECT_FALSE(triangle_box_overlap({{{2, 2, 2}, {3, 2, 2}, {2, 3, 2}}}, kUnit));
}

TEST(TriangleBox, LargeTriangleThroughTheBoxWithNoVertexInside) {
  EXPECT_TRUE(triangle_box_overlap({{{-10, -10, 0.5}, {10, -10, 0.5}, {0, 10, 0.5}}}, kUnit));
  // A small one in the same plane, off to the side.
  EXPECT_FALSE(triangle_box_overlap({{{-10, -10, 0.5}, {-9, -10, 0.5}, {-10, -9, 0.5}}}, kUnit));
}

TEST(TriangleBox, LyingOnAFaceTouches) {
  EXPECT_TRUE(triangle_box_overlap({{{0.2, 0.2, 1.0}, {0.8, 0.2, 1.0}, {0.5, 0.7, 1.0}}}, kUnit));
  EXPECT_TRUE(triangle_box_overlap({{{0.0, 0.2, 0.1}, {0.0, 0.9, 0.2}, {0.0, 0.5, 0.9}}}, kUnit));
  // The same a hair above the face does not.
  const double above = std::nextafter(1.0, 2.0);
  EXPECT_FALSE(triangle_box_overlap({{{0.2, 0.2, above}, {0.8, 0.2, above}, {0.5, 0.7, above}}}, kUnit));
}

TEST(TriangleBox, TouchingAtACornerOrAnEdge) {
  EXPECT_TRUE(triangle_box_overlap({{{1, 1, 1}, {2, 1, 1.5}, {1.5, 2, 2}}}, kUnit));
  EXPECT_TRUE(triangle_box_overlap({{{1, 1, -1}, {1, 1, 2}, {3, 3, 0.5}}}, kUnit));  // along edge x=y=1
  EXPECT_FALSE(triangle_box_overlap({{{1.001, 1, 1}, {2, 1, 1.5}, {1.5, 2, 2}}}, kUnit));
}

// The bounding boxes overlap and the triangle's plane crosses the box, yet they miss:
// only an edge x box-axis direction separates them.
TEST(TriangleBox, SeparatedOnlyByAnEdgeAxis) {
  const Triangle t{{{2.6, -0.5, 0.5}, {-0.5, 2.6, 0.5}, {2.6, 2.6, 0.5}}};
  EXPECT_FALSE(triangle_box_overlap(t, kUnit));
  const Triangle closer{{{2.4, -0.5, 0.5}, {-0.5, 2.4, 0.5}, {2.4, 2.4, 0.5}}};
  EXPECT_TRUE(triangle_box_overlap(closer, kUnit));
  // Tilted, so that the plane is not a box face plane either.
  const Triangle tilted{{{2.6, -0.5, 0.2}, {-0.5, 2.6, 0.8}, {2.6, 2.6, 0.9}}};
  EXPECT_FALSE(triangle_box_overlap(tilted, kUnit));
}

TEST(TriangleBox, DegenerateTriangles) {
  // Segments.
  EXPECT_TRUE(triangle_box_overlap({{{-1, 0.5, 0.5}, {2, 0.5, 0.5}, {2, 0.5, 0.5}}}, kUnit));
  EXPECT_TRUE(triangle_box_overlap({{{-1, -1, -1}, {2, 2, 2}, {0.5, 0.5, 0.5}}}, kUnit));  // collinear
  // x + z = 2.1 passes the box's edge x = z = 1; x + z = 1.9 cuts it.
  EXPECT_FALSE(triangle_box_overlap({{{-1, 0.5, 3.1}, {3.1, 0.5, -1}, {3.1, 0.5, -1}}}, kUnit));
  EXPECT_TRUE(triangle_box_overlap({{{-1, 0.5, 2.9}, {2.9, 0.5, -1}, {2.9, 0.5, -1}}}, kUnit));
  // Points.
  EXPECT_TRUE(triangle_box_overlap({{{0.3, 0.3, 0.3}, {0.3, 0.3, 0.3}, {0.3, 0.3, 0.3}}}, kUnit));
  EXPECT_TRUE(triangle_box_overlap({{{1, 0, 1}, {1, 0, 1}, {1, 0, 1}}}, kUnit));
  EXPECT_FALSE(triangle_box_overlap({{{1.5, 0.3, 0.3}, {1.5, 0.3, 0.3}, {1.5, 0.3, 0.3}}}, kUnit));
}

TEST(TriangleBox, InfiniteBoxesAndDegenerateBoxes) {
  const Box everything{{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}};
  EXPECT_TRUE(triangle_box_overlap({{{5, 6, 7}, {8, 9, 1}, {2, 3, 4}}}, everything));
  const Box half{{-kInf, -kInf, 1}, {kInf, kInf, kInf}};  // z >= 1
  EXPECT_TRUE(triangle_box_overlap({{{0, 0, 0}, {1, 0, 2}, {0, 1, 0}}}, half));
  EXPECT_FALSE(triangle_box_overlap({{{0, 0, 0}, {1, 0, 0.9}, {0, 1, 0}}}, half));
  const Box flat{{0, 0, 0.5}, {1, 1, 0.5}};  // a square
  EXPECT_TRUE(triangle_box_overlap({{{0.5, 0.5, 0}, {0.5, 0.5, 1}, {0.6, 0.6, 1}}}, flat));
  const Box empty{{1, 1, 1}, {0, 0, 0}};
  EXPECT_FALSE(triangle_box_overlap({{{0, 0, 0}, {1, 1, 1}, {0, 1, 0}}}, empty));
}

TEST(TriangleBox, UnusableVerticesNeverOverlap) {
  const Box everything{{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}};
  for (double bad : {kNaN, kInf, -kInf, 1e301}) {
    const Triangle t{{{0.5, 0.5, 0.5}, {bad, 0.5, 0.5}, {0.5, 0.6, 0.5}}};
    EXPECT_FALSE(vola::mesh::TriangleBoxTest(t).usable()) << bad;
    EXPECT_FALSE(triangle_box_overlap(t, kUnit)) << bad;
    EXPECT_FALSE(triangle_box_overlap(t, everything)) << bad;
  }
  EXPECT_TRUE(vola::mesh::TriangleBoxTest({{{1e299, 0, 0}, {0, -1e299, 0}, {0, 0, 1e299}}}).usable());
}

// The same shapes at scales from subnormal to 1e290: the answers do not change (the
// products inside the test would underflow or overflow without rescaling).
TEST(TriangleBox, AnswersDoNotDependOnScale) {
  const Triangle apart{{{2.6, -0.5, 0.5}, {-0.5, 2.6, 0.5}, {2.6, 2.6, 0.5}}};  // needs an edge axis
  const Triangle through{{{-10, -10, 0.5}, {10, -10, 0.7}, {0, 10, 0.5}}};
  const Triangle above{{{0.2, 0.2, 1.5}, {0.8, 0.2, 1.1}, {0.5, 0.7, 1.01}}};
  for (double scale : {1e-310, 1e-200, 1e-150, 1.0, 1e150, 1e290}) {
    const auto scaled = [&](Triangle t) {
      for (auto& v : t)
        for (auto& c : v) c *= scale;
      return t;
    };
    const Box box{{0, 0, 0}, {scale, scale, scale}};
    EXPECT_FALSE(triangle_box_overlap(scaled(apart), box)) << scale;
    EXPECT_TRUE(triangle_box_overlap(scaled(through), box)) << scale;
    EXPECT_FALSE(triangle_box_overlap(scaled(above), box)) << scale;
  }
}

// Random triangles and boxes: wherever the test says "touch", the triangle clipped to
// the box grown by a hair is not empty; wherever it says "miss", the triangle clipped
// to the box shrunk by a hair is empty.
TEST(TriangleBox, AgreesWithClipping) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> coord(-2.0, 3.0), size(0.0, 1.5);
  int touching = 0, missing = 0;
  for (int i = 0; i < 200000; ++i) {
    Triangle t;
    for (auto& v : t)
      for (auto& c : v) c = coord(rng);
    if (i % 5 == 1) t[2] = t[1];  // segments too
    Box b;
    for (int a = 0; a < 3; ++a) {
      b.min[a] = coord(rng);
      b.max[a] = b.min[a] + size(rng);
    }
    const bool overlap = triangle_box_overlap(t, b);
    if (overlap) {
      ++touching;
      EXPECT_TRUE(vola_mesh_test::clipped_triangle_meets_box(t, b, 1e-9)) << i;
    } else {
      ++missing;
      EXPECT_FALSE(vola_mesh_test::clipped_triangle_meets_box(t, b, -1e-9)) << i;
    }
  }
  EXPECT_GT(touching, 10000);
  EXPECT_GT(missing, 10000);
}

}  // namespace
}  // namespace test_triangle_box
