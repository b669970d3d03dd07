// The problem's world (types, objects, signatures, derived predicates), the
// ground state, and PDDL formulas and effects compiled against them. This
// mirrors btc's `btc_pddl::state`: same semantics, same order of changes.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "sexp.hpp"

namespace btc::detail
{

using Id = std::uint32_t;
/// A ground atom or fluent: predicate or function index, then object ids.
using Key = std::vector<Id>;

struct KeyHash
{
  std::size_t operator()(const Key& k) const noexcept
  {
    std::size_t h = 1469598103934665603ull;
    for(const Id x : k)
    {
      h = (h ^ x) * 1099511628211ull;
    }
    return h;
  }
};

struct State
{
  std::unordered_set<Key, KeyHash> facts;
  std::unordered_map<Key, double, KeyHash> fluents;
  std::unordered_set<Key, KeyHash> derived;
};

/// An object (by id) or a variable (by its slot in the environment).
struct Term
{
  bool var = false;
  Id id = 0;
  std::string name;  ///< the variable's name, for messages
};

struct NumExpr
{
  enum class Kind
  {
    Number,
    Fluent,
    Undefined,  ///< `?duration`, or an undeclared `(total-time)`
    Add,
    Sub,
    Mul,
    Div,
    Neg
  };
  Kind kind = Kind::Number;
  double value = 0;
  Id function = 0;
  std::vector<Term> args;
  std::unique_ptr<NumExpr> left, right;
};

/// A quantified variable: its slot and the objects it ranges over.
struct QVar
{
  std::string name;
  Id slot = 0;
  std::vector<Id> objects;
};

struct Formula
{
  enum class Kind
  {
    Atom,
    Equal,
    Not,
    And,
    Or,
    Imply,
    Exists,
    Forall,
    Less,
    LessEq,
    Greater,
    GreaterEq,
    NumEq
  };
  Kind kind = Kind::And;
  Id predicate = 0;
  bool derived = false;
  std::vector<Term> args;  ///< Atom: arguments; Equal: left, right
  std::vector<Formula> parts;  ///< And/Or: parts; Not: one; Imply: two; quantifiers: body
  std::vector<QVar> vars;
  std::unique_ptr<NumExpr> left, right;
};

struct Effect
{
  enum class Kind
  {
    Add,
    Delete,
    And,
    Forall,
    When,
    Assign,
    Increase,
    Decrease,
    ScaleUp,
    ScaleDown
  };
  Kind kind = Kind::And;
  Id predicate = 0;  ///< Add/Delete: the predicate; numeric: the function
  std::vector<Term> args;
  std::vector<Effect> parts;  ///< And: parts; Forall/When: body
  std::vector<QVar> vars;
  std::unique_ptr<Formula> condition;  ///< When
  std::unique_ptr<NumExpr> value;  ///< numeric updates
};

struct Signature
{
  std::string name;
  std::vector<std::vector<Id>> params;  ///< each parameter's types (`either`: several)
  bool derived = false;
};

struct DerivedRule
{
  Id predicate = 0;
  std::vector<QVar> params;
  Formula body;
};

/// The changes an effect makes, gathered before any applies.
struct Changes
{
  std::vector<Key> add;
  std::vector<Key> del;
  std::vector<std::pair<Key, double>> numeric;
};

class World
{
public:
  /// Reads the `.kb` file's expression; throws `KbError`.
  static World read(const Sexp& kb, const std::string& origin, State& initial);

  std::string domain;
  std::string problem;

  Formula compileFormula(const Sexp& s) const;
  Effect compileEffect(const Sexp& s) const;

  bool holds(const State& s, const Formula& f, std::vector<Id>& env) const;
  std::optional<double> value(const State& s, const NumExpr& e, std::vector<Id>& env) const;
  void collect(const State& s, const Effect& e, std::vector<Id>& env, Changes& out) const;
  void apply(State& s, Changes&& c) const;
  void closeDerived(State& s) const;
  std::string whyNot(const State& s, const Formula& f, std::vector<Id>& env) const;

  std::string showAtom(const Key& k) const;
  std::string showFluent(const Key& k) const;
  /// The slots a formula or effect needs (its deepest quantifier nesting).
  std::size_t slots() const { return max_slots_; }

  const Formula* goal() const { return goal_ ? &*goal_ : nullptr; }
  void setGoal(Formula g) { goal_ = std::move(g); }

private:
  struct Scope;
  bool isSubtype(Id a, Id b) const;
  bool fits(const std::vector<Id>& have, const std::vector<Id>& want) const;
  std::vector<Id> typeSpec(const Sexp& s) const;
  std::vector<QVar> typedVars(const Sexp& list, Scope& scope) const;
  Term term(const Sexp& s, const Scope& scope) const;
  std::vector<Term> args(const Sexp& l, const Signature& sig, const Scope& scope,
                         const char* what) const;
  Formula formula(const Sexp& s, Scope& scope) const;
  Effect effect(const Sexp& s, Scope& scope) const;
  std::unique_ptr<NumExpr> num(const Sexp& s, const Scope& scope) const;
  bool key(Id head, const std::vector<Term>& args, const std::vector<Id>& env, Key& out) const;
  std::string showTerm(const Term& t, const std::vector<Id>& env) const;
  std::string showGround(const Formula& atom, const std::vector<Id>& env) const;
  template <class F>
  bool eachBinding(const std::vector<QVar>& vars, std::size_t i, std::vector<Id>& env,
                   const F& f) const;

  std::vector<std::string> type_names_;
  std::unordered_map<std::string, Id> type_ids_;
  std::vector<std::vector<Id>> ancestors_;  ///< each type's ancestors, itself included
  Id object_type_ = 0;
  std::vector<std::string> object_names_;
  std::unordered_map<std::string, Id> object_ids_;
  std::vector<std::vector<Id>> object_types_;
  std::vector<Signature> predicates_;
  std::unordered_map<std::string, Id> predicate_ids_;
  std::vector<Signature> functions_;
  std::unordered_map<std::string, Id> function_ids_;
  std::vector<std::vector<DerivedRule>> strata_;
  std::optional<Formula> goal_;
  mutable std::size_t max_slots_ = 0;
};

}  // namespace btc::detail
