// A recursive-descent parser over a small token stream; the tree is a vector of nodes
// evaluated per point (no allocation per point).
#include "vola/filters/expression.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include "vola/error.hpp"

namespace vola::filters {

namespace {

struct Token {
  enum Type { name, number, op, lparen, rparen, end } type = end;
  std::string text;
  double value = 0.0;
  std::size_t position = 0;  // 1-based
};

[[noreturn]] void fail(std::size_t position, const std::string& what) {
  throw InvalidArgument("where: at character " + std::to_string(position) + ": " + what);
}

std::vector<Token> tokenize(const std::string& s) {
  std::vector<Token> tokens;
  std::size_t i = 0;
  while (i < s.size()) {
    const char c = s[i];
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    Token t;
    t.position = i + 1;
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      std::size_t j = i;
      while (j < s.size() && (std::isalnum(static_cast<unsigned char>(s[j])) || s[j] == '_')) ++j;
      t.type = Token::name;
      t.text = s.substr(i, j - i);
      i = j;
    } else if (std::isdigit(static_cast<unsigned char>(c)) || c == '.' ||
               ((c == '-' || c == '+') && i + 1 < s.size() &&
                (std::isdigit(static_cast<unsigned char>(s[i + 1])) || s[i + 1] == '.'))) {
      char* end = nullptr;
      t.value = std::strtod(s.c_str() + i, &end);
      const auto used = static_cast<std::size_t>(end - (s.c_str() + i));
      if (used == 0) fail(t.position, "'" + s.substr(i, 1) + "' does not start a number");
      t.type = Token::number;
      t.text = s.substr(i, used);
      i += used;
    } else if (c == '(' || c == ')') {
      t.type = c == '(' ? Token::lparen : Token::rparen;
      t.text = std::string(1, c);
      ++i;
    } else {
      static const char* const ops[] = {"&&", "||", "==", "!=", "<=", ">=", "<", ">", "!"};
      for (const char* op : ops) {
        const std::string o = op;
        if (s.compare(i, o.size(), o) == 0) {
          t.type = Token::op;
          t.text = o;
          break;
        }
      }
      if (t.type != Token::op) {
        if (c == '=' || c == '&' || c == '|')
          fail(t.position, std::string("'") + c + "' alone is not an operator (use ==, && or ||)");
        fail(t.position, std::string("unexpected '") + c + "'");
      }
      i += t.text.size();
    }
    tokens.push_back(t);
  }
  Token end;
  end.position = s.size() + 1;
  tokens.push_back(end);
  return tokens;
}

std::string describe(const Token& t) { return t.type == Token::end ? "the end" : "'" + t.text + "'"; }

}  // namespace

class ExpressionParser {
 public:
  ExpressionParser(Expression& e, std::vector<Token> tokens) : e_(e), tokens_(std::move(tokens)) {}

  std::size_t parse() {
    const std::size_t root = parse_or();
    if (peek().type != Token::end) fail(peek().position, "expected && or || or the end, found " + describe(peek()));
    return root;
  }

 private:
  const Token& peek() const { return tokens_[at_]; }
  bool accept_op(const char* op) {
    if (peek().type == Token::op && peek().text == op) {
      ++at_;
      return true;
    }
    return false;
  }
  std::size_t add(Expression::Node node) {
    // A chain of && or || makes a tree as deep as it is long: evaluation recurses it.
    if (e_.nodes_.size() >= 4096) fail(peek().position, "more than 4096 comparisons and operators");
    e_.nodes_.push_back(std::move(node));
    return e_.nodes_.size() - 1;
  }
  std::size_t parse_or() {
    std::size_t left = parse_and();
    while (accept_op("||")) {
      Expression::Node n;
      n.kind = Expression::Kind::or_;
      n.left = left;
      n.right = parse_and();
      left = add(std::move(n));
    }
    return left;
  }
  std::size_t parse_and() {
    std::size_t left = parse_unary();
    while (accept_op("&&")) {
      Expression::Node n;
      n.kind = Expression::Kind::and_;
      n.left = left;
      n.right = parse_unary();
      left = add(std::move(n));
    }
    return left;
  }
  // Nesting (! and parentheses) recurses, and so does evaluation over the tree: bounded,
  // as no filter a person writes nests this deep ("!!!!..." overflowed the stack).
  static constexpr int kMaxNesting = 256;
  void nest(std::size_t position) {
    if (++depth_ > kMaxNesting) fail(position, "nested more than " + std::to_string(kMaxNesting) + " deep");
  }
  std::size_t parse_unary() {
    if (peek().type == Token::op && peek().text == "!") {
      nest(peek().position);
      ++at_;
      Expression::Node n;
      n.kind = Expression::Kind::not_;
      n.left = parse_unary();
      --depth_;
      return add(std::move(n));
    }
    if (peek().type == Token::lparen) {
      const std::size_t open = peek().position;
      nest(open);
      ++at_;
      const std::size_t inner = parse_or();
      --depth_;
      if (peek().type != Token::rparen)
        fail(peek().position, "expected ')' to close the '(' at character " + std::to_string(open) + ", found " +
                                  describe(peek()));
      ++at_;
      return inner;
    }
    return parse_comparison();
  }
  Expression::Operand parse_operand() {
    const Token& t = peek();
    Expression::Operand o;
    o.position = t.position;
    if (t.type == Token::number) {
      o.number = t.value;
    } else if (t.type == Token::name) {
      o.is_dimension = true;
      o.name = t.text;
      o.slot = e_.slot_count_++;
    } else {
      fail(t.position, "expected a dimension name or a number, found " + describe(t));
    }
    ++at_;
    return o;
  }
  std::size_t parse_comparison() {
    Expression::Node n;
    n.a = parse_operand();
    const Token& t = peek();
    static const std::pair<const char*, Expression::Compare> ops[] = {
        {"==", Expression::Compare::eq}, {"!=", Expression::Compare::ne}, {"<", Expression::Compare::lt},
        {"<=", Expression::Compare::le}, {">", Expression::Compare::gt},  {">=", Expression::Compare::ge}};
    bool found = false;
    if (t.type == Token::op)
      for (const auto& [text, op] : ops)
        if (t.text == text) {
          n.op = op;
          found = true;
        }
    if (!found) fail(t.position, "expected a comparison (== != < <= > >=), found " + describe(t));
    ++at_;
    n.b = parse_operand();
    if (!n.a.is_dimension && !n.b.is_dimension)
      fail(n.a.position, "a comparison needs a dimension on one side (both sides are numbers)");
    return add(std::move(n));
  }

  Expression& e_;
  std::vector<Token> tokens_;
  std::size_t at_ = 0;
  int depth_ = 0;  // ! and ( being parsed
};

Expression::Expression(std::string text) : text_(std::move(text)) {
  auto tokens = tokenize(text_);
  if (tokens.size() == 1) fail(1, "the expression is empty");
  root_ = ExpressionParser(*this, std::move(tokens)).parse();
}

std::vector<std::string> Expression::dimensions() const {
  std::vector<std::string> names;
  const auto note = [&](const Operand& o) {
    if (!o.is_dimension) return;
    for (const auto& n : names)
      if (dimension_key(n) == dimension_key(o.name)) return;
    names.push_back(o.name);
  };
  // Nodes are stored children first, so slot order is the order of appearance.
  std::vector<const Operand*> operands(slot_count_);
  for (const auto& n : nodes_)
    if (n.kind == Kind::compare) {
      if (n.a.is_dimension) operands[n.a.slot] = &n.a;
      if (n.b.is_dimension) operands[n.b.slot] = &n.b;
    }
  for (const Operand* o : operands) note(*o);
  return names;
}

Expression::Bound Expression::bind(const PointCloud& cloud) const {
  Bound bound;
  bound.expression_ = this;
  bound.slots_.resize(slot_count_);
  const auto resolve = [&](const Operand& o) {
    if (!o.is_dimension) return;
    const auto d = find_dimension(cloud, o.name);
    // The expression is quoted: it may not be what the user typed (a pipeline's
    // filters.range limits become one), and the position must point into something.
    if (!d)
      throw InvalidArgument("where: at character " + std::to_string(o.position) + " of '" + text_ +
                            "': no dimension '" + o.name + "' in these points (they have " + dimension_list(cloud) +
                            ")");
    bound.slots_[o.slot] = *d;
  };
  for (const auto& n : nodes_)
    if (n.kind == Kind::compare) {
      resolve(n.a);
      resolve(n.b);
    }
  return bound;
}

bool Expression::eval(const Bound& bound, const PointCloud& cloud, std::size_t node, std::size_t point) const {
  const Node& n = nodes_[node];
  switch (n.kind) {
    case Kind::or_: return eval(bound, cloud, n.left, point) || eval(bound, cloud, n.right, point);
    case Kind::and_: return eval(bound, cloud, n.left, point) && eval(bound, cloud, n.right, point);
    case Kind::not_: return !eval(bound, cloud, n.left, point);
    case Kind::compare: break;
  }
  const double a = n.a.is_dimension ? value_of(cloud, bound.slots_[n.a.slot], point) : n.a.number;
  const double b = n.b.is_dimension ? value_of(cloud, bound.slots_[n.b.slot], point) : n.b.number;
  // A number typed against a value: equal within a trillionth, so that `Z == 414.53` finds
  // the points a LAS file stores as 41453 x 0.01 (414.53000000000003 as a double, which
  // the text writers print as 414.53), and `Z <= 414.53` keeps them.
  const bool typed = !n.a.is_dimension || !n.b.is_dimension;
  const bool equal = a == b || (typed && std::fabs(a - b) <= 1e-12 * std::max(std::fabs(a), std::fabs(b)));
  switch (n.op) {
    case Compare::eq:
      return equal;
    case Compare::ne:
      return !equal;
    case Compare::lt:
      return a < b && !equal;
    case Compare::le:
      return a <= b || equal;
    case Compare::gt:
      return a > b && !equal;
    case Compare::ge:
      return a >= b || equal;
  }
  return false;
}

bool Expression::Bound::operator()(const PointCloud& cloud, std::size_t point) const {
  return expression_->eval(*this, cloud, expression_->root_, point);
}

std::vector<bool> Expression::evaluate(const PointCloud& cloud) const {
  const Bound bound = bind(cloud);
  std::vector<bool> keep(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) keep[i] = bound(cloud, i);
  return keep;
}

}  // namespace vola::filters
