// `--where` expressions: comparisons of point dimensions with numbers (or with each
// other), joined by && and || with parentheses and !, as PDAL's filters.expression
// writes them:
//
//   Classification == 2 && (Intensity > 100 || ReturnNumber == 1)
//   !(z < 400) && HeightAboveGround <= 2.5
//
// Precedence, loosest first: ||, &&, !, comparison (== != < <= > >=). Dimension names are
// matched as dimensions.hpp says (case and underscores aside; PDAL's spellings work).
// Parsing needs no data; binding to a cloud checks the names. Errors are InvalidArgument
// naming the 1-based character where the expression goes wrong.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "vola/builder.hpp"
#include "vola/filters/dimensions.hpp"

namespace vola::filters {

class Expression {
 public:
  // Throws InvalidArgument "where: at character N: ..." for an expression that does not parse.
  explicit Expression(std::string text);

  const std::string& text() const noexcept { return text_; }
  // The dimension names it uses, in order of appearance (repeats kept once).
  std::vector<std::string> dimensions() const;

  // The expression with its names resolved against `cloud`'s dimensions; throws
  // InvalidArgument naming the unknown dimension, its position and the cloud's dimensions.
  class Bound {
   public:
    bool operator()(const PointCloud& cloud, std::size_t point) const;

   private:
    friend class Expression;
    const Expression* expression_ = nullptr;
    std::vector<Dimension> slots_;  // one per Node with a dimension operand
  };
  Bound bind(const PointCloud& cloud) const;

  // Which points of `cloud` it holds for.
  std::vector<bool> evaluate(const PointCloud& cloud) const;

  // One node of the parsed tree (public for Bound; not an interface).
  struct Operand {
    bool is_dimension = false;
    double number = 0.0;
    std::string name;        // when is_dimension
    std::size_t slot = 0;    // index into Bound::slots_
    std::size_t position = 0;  // 1-based character of the name
  };
  enum class Kind { or_, and_, not_, compare };
  enum class Compare { eq, ne, lt, le, gt, ge };
  struct Node {
    Kind kind = Kind::compare;
    std::size_t left = 0, right = 0;  // child nodes (not_: left only)
    Compare op = Compare::eq;
    Operand a, b;
  };

 private:
  bool eval(const Bound& bound, const PointCloud& cloud, std::size_t node, std::size_t point) const;
  std::string text_;
  std::vector<Node> nodes_;
  std::size_t root_ = 0;
  std::size_t slot_count_ = 0;
  friend class ExpressionParser;
};

}  // namespace vola::filters
