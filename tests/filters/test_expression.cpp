// The --where parser: precedence, names as users spell them, and errors that name the
// place in the expression. Results are held to a plain evaluation written in the test.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "vola/error.hpp"
#include "vola/filters/expression.hpp"

namespace {

using vola::filters::Expression;

// Points with x y z and two columns: classification (0..5) and intensity (0..99).
vola::PointCloud sample_cloud() {
  vola::PointCloud cloud;
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> cls(0, 5), intensity(0, 99), coord(-20, 20);
  cloud.attributes.push_back({"classification", vola::ValueType::u8, vola::Reduction::majority, {}});
  cloud.attributes.push_back({"intensity", vola::ValueType::u16, vola::Reduction::mean, {}});
  cloud.attributes.push_back({"return_number", vola::ValueType::u8, vola::Reduction::last, {}});
  for (int i = 0; i < 500; ++i) {
    for (int a = 0; a < 3; ++a) cloud.xyz.push_back(coord(rng));
    cloud.attributes[0].values.push_back(cls(rng));
    cloud.attributes[1].values.push_back(intensity(rng));
    cloud.attributes[2].values.push_back(1 + i % 3);
  }
  return cloud;
}

template <class Reference>
void expect_same(const std::string& text, Reference reference) {
  const vola::PointCloud cloud = sample_cloud();
  const std::vector<bool> got = Expression(text).evaluate(cloud);
  std::size_t held = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double x = cloud.xyz[3 * i], z = cloud.xyz[3 * i + 2];
    const double c = cloud.attributes[0].values[i], in = cloud.attributes[1].values[i];
    const double r = cloud.attributes[2].values[i];
    ASSERT_EQ(got[i], reference(x, z, c, in, r)) << text << " at point " << i;
    held += got[i];
  }
  EXPECT_GT(held, 0u) << text << " holds for no point: a weak case";
  EXPECT_LT(held, cloud.size()) << text << " holds for every point: a weak case";
}

TEST(Expression, ComparisonsOnAxesAndColumns) {
  expect_same("Classification == 2", [](double, double, double c, double, double) { return c == 2; });
  expect_same("intensity != 50", [](double, double, double, double in, double) { return in != 50; });
  expect_same("z < 0", [](double, double z, double, double, double) { return z < 0; });
  expect_same("Z <= -3.5", [](double, double z, double, double, double) { return z <= -3.5; });
  expect_same("x > 10", [](double x, double, double, double, double) { return x > 10; });
  expect_same("X >= 1e1", [](double x, double, double, double, double) { return x >= 10; });
  expect_same("5 < intensity", [](double, double, double, double in, double) { return in > 5; });
  expect_same("ReturnNumber == 1", [](double, double, double, double, double r) { return r == 1; });
  expect_same("x < z", [](double x, double z, double, double, double) { return x < z; });
}

TEST(Expression, ATypedNumberEqualsTheStoredDecimalsOfAValue) {
  // LAS stores 414.53 as 41453 x 0.01, 414.53000000000003 as a double: `Z == 414.53` found
  // none of such points, and `Z <= 414.53` dropped them.
  vola::PointCloud cloud;
  for (const std::int32_t stored : {41452, 41453, 41453, 41454})
    cloud.xyz.insert(cloud.xyz.end(), {0.0, 0.0, stored * 0.01});
  ASSERT_NE(cloud.xyz[5], 414.53);  // the case is real
  const auto count = [&](const std::string& text) {
    const std::vector<bool> keep = Expression(text).evaluate(cloud);
    return std::count(keep.begin(), keep.end(), true);
  };
  EXPECT_EQ(count("Z == 414.53"), 2);
  EXPECT_EQ(count("Z != 414.53"), 2);
  EXPECT_EQ(count("Z <= 414.53"), 3);
  EXPECT_EQ(count("Z < 414.53"), 1);
  EXPECT_EQ(count("Z >= 414.53"), 3);
  EXPECT_EQ(count("Z > 414.53"), 1);
  EXPECT_EQ(count("414.53 == Z"), 2);
  // Values a whole unit of the stored precision apart stay apart.
  EXPECT_EQ(count("Z == 414.52"), 1);
}

TEST(Expression, AndBindsTighterThanOr) {
  expect_same("classification == 1 || classification == 2 && intensity > 50",
              [](double, double, double c, double in, double) { return c == 1 || (c == 2 && in > 50); });
  expect_same("classification == 2 && intensity > 50 || classification == 1",
              [](double, double, double c, double in, double) { return (c == 2 && in > 50) || c == 1; });
  expect_same("(classification == 1 || classification == 2) && intensity > 50",
              [](double, double, double c, double in, double) { return (c == 1 || c == 2) && in > 50; });
}

TEST(Expression, NotAppliesToWhatFollowsIt) {
  expect_same("!classification == 2 && z > 0",
              [](double, double z, double c, double, double) { return !(c == 2) && z > 0; });
  expect_same("!(classification == 2 && z > 0)",
              [](double, double z, double c, double, double) { return !(c == 2 && z > 0); });
  expect_same("!!(x > 0)", [](double x, double, double, double, double) { return x > 0; });
}

// The message of the InvalidArgument `text` raises, parsing and binding.
std::string error_of(const std::string& text) {
  try {
    Expression(text).evaluate(sample_cloud());
  } catch (const vola::InvalidArgument& e) {
    return e.what();
  }
  return "";
}

TEST(Expression, ErrorsNameThePositionAndWhatWasExpected) {
  EXPECT_EQ(error_of("classification = 2"), "where: at character 16: '=' alone is not an operator (use ==, && or ||)");
  EXPECT_EQ(error_of("classification == "), "where: at character 19: expected a dimension name or a number, found the end");
  EXPECT_EQ(error_of("(z > 1"), "where: at character 7: expected ')' to close the '(' at character 1, found the end");
  EXPECT_EQ(error_of("z > 1 z"), "where: at character 7: expected && or || or the end, found 'z'");
  EXPECT_EQ(error_of("z 1"), "where: at character 3: expected a comparison (== != < <= > >=), found '1'");
  EXPECT_EQ(error_of("1 < 2"), "where: at character 1: a comparison needs a dimension on one side (both sides are numbers)");
  EXPECT_EQ(error_of(""), "where: at character 1: the expression is empty");
  EXPECT_EQ(error_of("z > 1 # 2"), "where: at character 7: unexpected '#'");
}

TEST(Expression, UnknownDimensionsAreNamedWithTheOnesThePointsHave) {
  EXPECT_EQ(error_of("z > 1 && Colour == 3"),
            "where: at character 10 of 'z > 1 && Colour == 3': no dimension 'Colour' in these points (they have x, y, "
            "z, classification, "
            "intensity, return_number)");
  EXPECT_EQ(error_of("HeightAboveGround > 2"),
            "where: at character 1 of 'HeightAboveGround > 2': no dimension 'HeightAboveGround' in these points (they "
            "have x, y, z, "
            "classification, intensity, return_number)");
}

TEST(Expression, ListsItsDimensionsOnceInOrder) {
  const Expression e("Z > 1 && (intensity < 3 || z < 0) && Classification == 2");
  EXPECT_EQ(e.dimensions(), (std::vector<std::string>{"Z", "intensity", "Classification"}));
}

}  // namespace

// Parsing and evaluation recurse: nesting and length are bounded with an error, where
// "!!!!..." used to overflow the stack (fuzz_filters_read).
TEST(Expression, DeepNestingAndEndlessChainsAreRefused) {
  EXPECT_THROW(vola::filters::Expression(std::string(300, '!') + "x == 1"), vola::InvalidArgument);
  EXPECT_THROW(vola::filters::Expression(std::string(300, '(') + "x == 1" + std::string(300, ')')),
               vola::InvalidArgument);
  std::string chain = "x == 1";
  for (int i = 0; i < 5000; ++i) chain += " && x == 1";
  EXPECT_THROW(vola::filters::Expression{chain}, vola::InvalidArgument);
  EXPECT_NO_THROW(vola::filters::Expression(std::string(200, '!') + "x == 1"));
}
