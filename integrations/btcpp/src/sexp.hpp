// PDDL text as s-expressions, tokenised as btc's lexer does
// (pddl/src/lexer.rs): names, variables and keywords lower-cased, `;`
// comments, numbers, a lone `-`.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace btc::detail
{

struct Sexp
{
  enum class Kind
  {
    Name,     ///< a name or an operator (`=`, `<=`, `+` ...), lower-cased
    Var,      ///< `?x`, stored without the `?`
    Keyword,  ///< `:init`, stored without the `:`
    Number,
    Dash,  ///< a lone `-`
    List
  };
  Kind kind = Kind::List;
  std::string text;
  double number = 0;
  std::vector<Sexp> items;
  std::size_t offset = 0;  ///< byte offset in the text read

  bool isList() const { return kind == Kind::List; }
  bool isName(const char* n) const { return kind == Kind::Name && text == n; }
  /// The list's first item when it is a name, else null.
  const std::string* head() const;
  /// How the expression reads back, for messages.
  std::string show() const;
};

/// Reads every expression of `text`. Throws `KbError` with `origin`, the
/// line and the column of the first problem (an unclosed `(`, a stray `)`,
/// a word PDDL does not allow).
std::vector<Sexp> readSexps(const std::string& text, const std::string& origin);

/// Reads exactly one expression (a formula or effect attribute).
Sexp readOne(const std::string& text, const std::string& what);

}  // namespace btc::detail
