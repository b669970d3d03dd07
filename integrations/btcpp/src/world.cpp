#include "world.hpp"

#include <algorithm>
#include <map>

#include "btc/kb.hpp"

namespace btc::detail
{

namespace
{

[[noreturn]] void fail(const std::string& msg)
{
  throw KbError(msg);
}

std::string plural(std::size_t n, const char* one)
{
  return std::to_string(n) + " " + one + (n == 1 ? "" : "s");
}

}  // namespace

/// Variables in scope, innermost last, each with its environment slot.
struct World::Scope
{
  std::vector<std::pair<std::string, Id>> vars;

  const std::pair<std::string, Id>* find(const std::string& name) const
  {
    for(auto it = vars.rbegin(); it != vars.rend(); ++it)
    {
      if(it->first == name)
      {
        return &*it;
      }
    }
    return nullptr;
  }
};

// ---------------------------------------------------------------- types

bool World::isSubtype(Id a, Id b) const
{
  const auto& anc = ancestors_[a];
  return a == b || b == object_type_ || std::find(anc.begin(), anc.end(), b) != anc.end();
}

bool World::fits(const std::vector<Id>& have, const std::vector<Id>& want) const
{
  return std::all_of(have.begin(), have.end(), [&](Id h) {
    return std::any_of(want.begin(), want.end(), [&](Id w) { return isSubtype(h, w); });
  });
}

std::vector<Id> World::typeSpec(const Sexp& s) const
{
  auto one = [&](const Sexp& n) -> Id {
    if(n.kind != Sexp::Kind::Name)
    {
      fail("`" + n.show() + "` is not a type");
    }
    auto it = type_ids_.find(n.text);
    if(it == type_ids_.end())
    {
      fail("`" + n.text + "` is not a type of domain " + domain);
    }
    return it->second;
  };
  if(s.isList())
  {
    const std::string* h = s.head();
    if(h == nullptr || *h != "either" || s.items.size() < 2)
    {
      fail("`" + s.show() + "` is not a type (a name or `(either t1 t2 ...)`)");
    }
    std::vector<Id> out;
    for(std::size_t i = 1; i < s.items.size(); ++i)
    {
      out.push_back(one(s.items[i]));
    }
    return out;
  }
  return { one(s) };
}

std::vector<QVar> World::typedVars(const Sexp& list, Scope& scope) const
{
  if(!list.isList())
  {
    fail("`" + list.show() + "` is not a variable list such as `(?x - t)`");
  }
  std::vector<QVar> vars;
  std::vector<std::vector<Id>> types;
  std::size_t untyped_from = 0;
  const auto& items = list.items;
  for(std::size_t i = 0; i < items.size(); ++i)
  {
    if(items[i].kind == Sexp::Kind::Var)
    {
      vars.push_back(QVar{ items[i].text, 0, {} });
      continue;
    }
    if(items[i].kind == Sexp::Kind::Dash && i + 1 < items.size() && untyped_from < vars.size())
    {
      const auto t = typeSpec(items[++i]);
      while(types.size() < vars.size())
      {
        types.push_back(t);
      }
      untyped_from = vars.size();
      continue;
    }
    fail("`" + list.show() + "` is not a variable list such as `(?x - t)`");
  }
  while(types.size() < vars.size())
  {
    types.push_back({ object_type_ });
  }
  for(std::size_t v = 0; v < vars.size(); ++v)
  {
    for(Id o = 0; o < object_names_.size(); ++o)
    {
      if(fits(object_types_[o], types[v]))
      {
        vars[v].objects.push_back(o);
      }
    }
    vars[v].slot = static_cast<Id>(scope.vars.size());
    scope.vars.emplace_back(vars[v].name, vars[v].slot);
    max_slots_ = std::max(max_slots_, scope.vars.size());
  }
  return vars;
}

// ------------------------------------------------------------- compiling

Term World::term(const Sexp& s, const Scope& scope) const
{
  if(s.kind == Sexp::Kind::Var)
  {
    const auto* v = scope.find(s.text);
    if(v == nullptr)
    {
      fail("`?" + s.text + "` is not bound: the formulas of a tree are ground");
    }
    return Term{ true, v->second, s.text };
  }
  if(s.kind == Sexp::Kind::Name)
  {
    auto it = object_ids_.find(s.text);
    if(it == object_ids_.end())
    {
      fail("`" + s.text + "` is not an object of problem " + problem);
    }
    return Term{ false, it->second, s.text };
  }
  fail("`" + s.show() + "` is not a variable or an object name");
}

std::vector<Term> World::args(const Sexp& l, const Signature& sig, const Scope& scope,
                              const char* what) const
{
  const std::size_t n = l.items.size() - 1;
  if(n != sig.params.size())
  {
    fail(std::string(what) + " `" + sig.name + "` takes " +
         plural(sig.params.size(), "argument") + ", found " + std::to_string(n) + " in `" +
         l.show() + "`");
  }
  std::vector<Term> out;
  for(std::size_t i = 0; i < n; ++i)
  {
    Term t = term(l.items[i + 1], scope);
    if(!t.var && !fits(object_types_[t.id], sig.params[i]))
    {
      std::string want;
      for(const Id w : sig.params[i])
      {
        want += (want.empty() ? "" : " or ") + type_names_[w];
      }
      fail("`" + t.name + "` is not of type " + want + ", as argument " +
           std::to_string(i + 1) + " of `" + sig.name + "` needs");
    }
    out.push_back(std::move(t));
  }
  return out;
}

std::unique_ptr<NumExpr> World::num(const Sexp& s, const Scope& scope) const
{
  auto e = std::make_unique<NumExpr>();
  if(s.kind == Sexp::Kind::Number)
  {
    e->kind = NumExpr::Kind::Number;
    e->value = s.number;
    return e;
  }
  if(s.kind == Sexp::Kind::Var && s.text == "duration")
  {
    // A ground effect has no duration to refer to: btc's KB reads it as
    // undefined too.
    e->kind = NumExpr::Kind::Undefined;
    return e;
  }
  if(!s.isList() || s.items.empty())
  {
    fail("`" + s.show() + "` is not a number or a function such as `(total-cost)`");
  }
  const Sexp& h = s.items[0];
  NumExpr::Kind op = NumExpr::Kind::Number;
  if(h.kind == Sexp::Kind::Dash)
  {
    op = NumExpr::Kind::Sub;
  }
  else if(h.isName("+"))
  {
    op = NumExpr::Kind::Add;
  }
  else if(h.isName("*"))
  {
    op = NumExpr::Kind::Mul;
  }
  else if(h.isName("/"))
  {
    op = NumExpr::Kind::Div;
  }
  if(op != NumExpr::Kind::Number)
  {
    if(op == NumExpr::Kind::Sub && s.items.size() == 2)
    {
      e->kind = NumExpr::Kind::Neg;
      e->left = num(s.items[1], scope);
      return e;
    }
    if(s.items.size() < 3)
    {
      fail("`" + s.show() + "` needs two operands");
    }
    // (+ a b c) folds left: ((a + b) + c), as btc reads it.
    auto acc = num(s.items[1], scope);
    for(std::size_t i = 2; i < s.items.size(); ++i)
    {
      auto b = std::make_unique<NumExpr>();
      b->kind = op;
      b->left = std::move(acc);
      b->right = num(s.items[i], scope);
      acc = std::move(b);
    }
    return acc;
  }
  if(h.kind != Sexp::Kind::Name)
  {
    fail("`" + s.show() + "` is not a numeric expression");
  }
  auto it = function_ids_.find(h.text);
  if(it == function_ids_.end())
  {
    if(h.text == "total-time" && s.items.size() == 1)
    {
      e->kind = NumExpr::Kind::Undefined;
      return e;
    }
    fail("`" + h.text + "` is not a function of domain " + domain);
  }
  e->kind = NumExpr::Kind::Fluent;
  e->function = it->second;
  e->args = args(s, functions_[it->second], scope, "function");
  return e;
}

Formula World::formula(const Sexp& s, Scope& scope) const
{
  Formula f;
  if(!s.isList())
  {
    fail("`" + s.show() + "` is not a formula such as `(on ?x ?y)`");
  }
  if(s.items.empty())
  {
    f.kind = Formula::Kind::And;  // `()`: nothing required
    return f;
  }
  const std::string* hp = s.head();
  if(hp == nullptr)
  {
    fail("`" + s.show() + "` does not start with a predicate or a connective such as `and`");
  }
  const std::string& h = *hp;
  const std::size_t n = s.items.size() - 1;
  auto arity = [&](std::size_t want) {
    if(n != want)
    {
      fail("`" + h + "` takes " + plural(want, "argument") + ", found " + std::to_string(n) +
           " in `" + s.show() + "`");
    }
  };
  if(h == "and" || h == "or")
  {
    f.kind = h == "and" ? Formula::Kind::And : Formula::Kind::Or;
    for(std::size_t i = 1; i <= n; ++i)
    {
      f.parts.push_back(formula(s.items[i], scope));
    }
    return f;
  }
  if(h == "not")
  {
    arity(1);
    f.kind = Formula::Kind::Not;
    f.parts.push_back(formula(s.items[1], scope));
    return f;
  }
  if(h == "imply")
  {
    arity(2);
    f.kind = Formula::Kind::Imply;
    f.parts.push_back(formula(s.items[1], scope));
    f.parts.push_back(formula(s.items[2], scope));
    return f;
  }
  if(h == "exists" || h == "forall")
  {
    arity(2);
    f.kind = h == "exists" ? Formula::Kind::Exists : Formula::Kind::Forall;
    const std::size_t mark = scope.vars.size();
    f.vars = typedVars(s.items[1], scope);
    f.parts.push_back(formula(s.items[2], scope));
    scope.vars.resize(mark);
    return f;
  }
  if(h == "=" && std::none_of(s.items.begin() + 1, s.items.end(),
                              [](const Sexp& a) { return a.isList(); }))
  {
    arity(2);
    f.kind = Formula::Kind::Equal;
    f.args.push_back(term(s.items[1], scope));
    f.args.push_back(term(s.items[2], scope));
    return f;
  }
  if(h == "=" || h == "<" || h == "<=" || h == ">" || h == ">=")
  {
    arity(2);
    f.kind = h == "="    ? Formula::Kind::NumEq :
             h == "<"    ? Formula::Kind::Less :
             h == "<="   ? Formula::Kind::LessEq :
             h == ">"    ? Formula::Kind::Greater :
                           Formula::Kind::GreaterEq;
    f.left = num(s.items[1], scope);
    f.right = num(s.items[2], scope);
    return f;
  }
  if(h == "+" || h == "*" || h == "/")
  {
    fail("`" + s.show() + "` is a numeric expression, not a formula");
  }
  if(h == "preference")
  {
    fail("`preference` (PDDL3 preferences) is not supported: `" + s.show() + "`");
  }
  if((h == "at" || h == "over") && n == 2 &&
     (s.items[1].isName("start") || s.items[1].isName("end") || s.items[1].isName("all")))
  {
    fail("a timed condition is allowed only in a durative action: `" + s.show() + "`");
  }
  auto it = predicate_ids_.find(h);
  if(it == predicate_ids_.end())
  {
    fail("`" + h + "` is not a predicate of domain " + domain);
  }
  f.kind = Formula::Kind::Atom;
  f.predicate = it->second;
  f.derived = predicates_[it->second].derived;
  f.args = args(s, predicates_[it->second], scope, "predicate");
  return f;
}

Effect World::effect(const Sexp& s, Scope& scope) const
{
  Effect e;
  if(!s.isList())
  {
    fail("`" + s.show() + "` is not an effect such as `(on ?x ?y)`");
  }
  if(s.items.empty())
  {
    e.kind = Effect::Kind::And;
    return e;
  }
  const std::string* hp = s.head();
  if(hp == nullptr)
  {
    fail("`" + s.show() + "` does not start with a predicate or `and`, `not`, `forall`, `when`");
  }
  const std::string& h = *hp;
  const std::size_t n = s.items.size() - 1;
  auto count = [&](std::size_t want) {
    if(n != want)
    {
      fail("`" + h + "` takes " + plural(want, "argument") + ", found " + std::to_string(n) +
           " in `" + s.show() + "`");
    }
  };
  if(h == "and")
  {
    for(std::size_t i = 1; i <= n; ++i)
    {
      e.parts.push_back(effect(s.items[i], scope));
    }
    return e;
  }
  if(h == "not")
  {
    count(1);
    const Sexp& a = s.items[1];
    const std::string* ah = a.head();
    auto it = ah ? predicate_ids_.find(*ah) : predicate_ids_.end();
    if(ah == nullptr || it == predicate_ids_.end())
    {
      fail("`" + s.show() + "`: only an atom of a domain predicate can be deleted");
    }
    e.kind = Effect::Kind::Delete;
    e.predicate = it->second;
    e.args = args(a, predicates_[it->second], scope, "predicate");
    return e;
  }
  if(h == "forall")
  {
    count(2);
    e.kind = Effect::Kind::Forall;
    const std::size_t mark = scope.vars.size();
    e.vars = typedVars(s.items[1], scope);
    e.parts.push_back(effect(s.items[2], scope));
    scope.vars.resize(mark);
    return e;
  }
  if(h == "when")
  {
    count(2);
    e.kind = Effect::Kind::When;
    e.condition = std::make_unique<Formula>(formula(s.items[1], scope));
    e.parts.push_back(effect(s.items[2], scope));
    return e;
  }
  if(h == "assign" || h == "increase" || h == "decrease" || h == "scale-up" ||
     h == "scale-down")
  {
    count(2);
    e.kind = h == "assign"   ? Effect::Kind::Assign :
             h == "increase" ? Effect::Kind::Increase :
             h == "decrease" ? Effect::Kind::Decrease :
             h == "scale-up" ? Effect::Kind::ScaleUp :
                               Effect::Kind::ScaleDown;
    const Sexp& fl = s.items[1];
    const std::string* fh = fl.head();
    if(fh == nullptr)
    {
      fail("`" + fl.show() + "` is not a function such as `(total-cost)`");
    }
    auto it = function_ids_.find(*fh);
    if(it == function_ids_.end())
    {
      fail("`" + *fh + "` is not a function of domain " + domain);
    }
    e.predicate = it->second;
    e.args = args(fl, functions_[it->second], scope, "function");
    e.value = num(s.items[2], scope);
    return e;
  }
  if((h == "at" && n == 2 && (s.items[1].isName("start") || s.items[1].isName("end"))) ||
     h == "or" || h == "exists" || h == "imply" || h == "=" || h == "<" || h == "<=" ||
     h == ">" || h == ">=" || h == "+" || h == "*" || h == "/")
  {
    fail("`" + s.show() + "` is not an effect (`and`, `not`, `forall`, `when`, a numeric update "
                          "or an atom)");
  }
  auto it = predicate_ids_.find(h);
  if(it == predicate_ids_.end())
  {
    fail("`" + h + "` is not a predicate of domain " + domain);
  }
  if(predicates_[it->second].derived)
  {
    fail("`" + h + "` is a derived predicate: effects cannot change it");
  }
  e.kind = Effect::Kind::Add;
  e.predicate = it->second;
  e.args = args(s, predicates_[it->second], scope, "predicate");
  return e;
}

Formula World::compileFormula(const Sexp& s) const
{
  Scope scope;
  return formula(s, scope);
}

Effect World::compileEffect(const Sexp& s) const
{
  Scope scope;
  return effect(s, scope);
}

// ------------------------------------------------------------ evaluating

bool World::key(Id head, const std::vector<Term>& args, const std::vector<Id>& env,
                Key& out) const
{
  out.clear();
  out.push_back(head);
  for(const Term& t : args)
  {
    out.push_back(t.var ? env[t.id] : t.id);
  }
  return true;
}

template <class F>
bool World::eachBinding(const std::vector<QVar>& vars, std::size_t i, std::vector<Id>& env,
                        const F& f) const
{
  if(i == vars.size())
  {
    return f();
  }
  for(const Id o : vars[i].objects)
  {
    env[vars[i].slot] = o;
    if(eachBinding(vars, i + 1, env, f))
    {
      return true;
    }
  }
  return false;
}

bool World::holds(const State& s, const Formula& f, std::vector<Id>& env) const
{
  switch(f.kind)
  {
    case Formula::Kind::Atom: {
      Key k;
      key(f.predicate, f.args, env, k);
      return f.derived ? s.derived.count(k) > 0 : s.facts.count(k) > 0;
    }
    case Formula::Kind::Equal: {
      const Id a = f.args[0].var ? env[f.args[0].id] : f.args[0].id;
      const Id b = f.args[1].var ? env[f.args[1].id] : f.args[1].id;
      return a == b;
    }
    case Formula::Kind::Not:
      return !holds(s, f.parts[0], env);
    case Formula::Kind::And:
      return std::all_of(f.parts.begin(), f.parts.end(),
                         [&](const Formula& p) { return holds(s, p, env); });
    case Formula::Kind::Or:
      return std::any_of(f.parts.begin(), f.parts.end(),
                         [&](const Formula& p) { return holds(s, p, env); });
    case Formula::Kind::Imply:
      return !holds(s, f.parts[0], env) || holds(s, f.parts[1], env);
    case Formula::Kind::Exists:
      return eachBinding(f.vars, 0, env, [&] { return holds(s, f.parts[0], env); });
    case Formula::Kind::Forall:
      return !eachBinding(f.vars, 0, env, [&] { return !holds(s, f.parts[0], env); });
    default: {
      const auto a = value(s, *f.left, env);
      const auto b = value(s, *f.right, env);
      if(!a || !b)
      {
        return false;
      }
      switch(f.kind)
      {
        case Formula::Kind::Less:
          return *a < *b;
        case Formula::Kind::LessEq:
          return *a <= *b;
        case Formula::Kind::Greater:
          return *a > *b;
        case Formula::Kind::GreaterEq:
          return *a >= *b;
        default:
          return *a == *b;
      }
    }
  }
}

std::optional<double> World::value(const State& s, const NumExpr& e, std::vector<Id>& env) const
{
  switch(e.kind)
  {
    case NumExpr::Kind::Number:
      return e.value;
    case NumExpr::Kind::Undefined:
      return std::nullopt;
    case NumExpr::Kind::Fluent: {
      Key k;
      key(e.function, e.args, env, k);
      auto it = s.fluents.find(k);
      if(it == s.fluents.end())
      {
        return std::nullopt;
      }
      return it->second;
    }
    case NumExpr::Kind::Neg: {
      const auto a = value(s, *e.left, env);
      return a ? std::optional<double>(-*a) : std::nullopt;
    }
    default: {
      const auto a = value(s, *e.left, env);
      const auto b = value(s, *e.right, env);
      if(!a || !b)
      {
        return std::nullopt;
      }
      switch(e.kind)
      {
        case NumExpr::Kind::Add:
          return *a + *b;
        case NumExpr::Kind::Sub:
          return *a - *b;
        case NumExpr::Kind::Mul:
          return *a * *b;
        default:
          return *a / *b;
      }
    }
  }
}

void World::collect(const State& s, const Effect& e, std::vector<Id>& env, Changes& out) const
{
  switch(e.kind)
  {
    case Effect::Kind::Add:
    case Effect::Kind::Delete: {
      Key k;
      key(e.predicate, e.args, env, k);
      (e.kind == Effect::Kind::Add ? out.add : out.del).push_back(std::move(k));
      return;
    }
    case Effect::Kind::And:
      for(const Effect& p : e.parts)
      {
        collect(s, p, env, out);
      }
      return;
    case Effect::Kind::Forall:
      eachBinding(e.vars, 0, env, [&] {
        collect(s, e.parts[0], env, out);
        return false;
      });
      return;
    case Effect::Kind::When:
      if(holds(s, *e.condition, env))
      {
        collect(s, e.parts[0], env, out);
      }
      return;
    default: {
      Key k;
      key(e.predicate, e.args, env, k);
      auto it = s.fluents.find(k);
      const bool has_old = it != s.fluents.end();
      const double old = has_old ? it->second : 0.0;
      const auto v = value(s, *e.value, env);
      std::optional<double> now;
      if(v && (has_old || e.kind == Effect::Kind::Assign))
      {
        switch(e.kind)
        {
          case Effect::Kind::Assign:
            now = *v;
            break;
          case Effect::Kind::Increase:
            now = old + *v;
            break;
          case Effect::Kind::Decrease:
            now = old - *v;
            break;
          case Effect::Kind::ScaleUp:
            now = old * *v;
            break;
          default:
            now = old / *v;
            break;
        }
      }
      // An update of an undefined value changes nothing (btc's KB ignores
      // it the same way; its validator reports it).
      if(now)
      {
        out.numeric.emplace_back(std::move(k), *now);
      }
      return;
    }
  }
}

void World::apply(State& s, Changes&& c) const
{
  for(const Key& k : c.del)
  {
    s.facts.erase(k);
  }
  for(Key& k : c.add)
  {
    s.facts.insert(std::move(k));
  }
  for(auto& [k, v] : c.numeric)
  {
    s.fluents[k] = v;
  }
  closeDerived(s);
}

void World::closeDerived(State& s) const
{
  if(strata_.empty())
  {
    return;
  }
  s.derived.clear();
  std::vector<Id> env(std::max<std::size_t>(max_slots_, 1));
  for(const auto& stratum : strata_)
  {
    while(true)
    {
      std::vector<Key> found;
      for(const DerivedRule& r : stratum)
      {
        eachBinding(r.params, 0, env, [&] {
          Key k{ r.predicate };
          for(const QVar& p : r.params)
          {
            k.push_back(env[p.slot]);
          }
          if(s.derived.count(k) == 0 && holds(s, r.body, env))
          {
            found.push_back(std::move(k));
          }
          return false;
        });
      }
      if(found.empty())
      {
        break;
      }
      for(Key& k : found)
      {
        s.derived.insert(std::move(k));
      }
    }
  }
}

// ------------------------------------------------------------ messages

std::string World::showAtom(const Key& k) const
{
  std::string s = "(" + predicates_[k[0]].name;
  for(std::size_t i = 1; i < k.size(); ++i)
  {
    s += " " + object_names_[k[i]];
  }
  return s + ")";
}

std::string World::showFluent(const Key& k) const
{
  std::string s = "(" + functions_[k[0]].name;
  for(std::size_t i = 1; i < k.size(); ++i)
  {
    s += " " + object_names_[k[i]];
  }
  return s + ")";
}

std::string World::showTerm(const Term& t, const std::vector<Id>& env) const
{
  return object_names_[t.var ? env[t.id] : t.id];
}

std::string World::showGround(const Formula& atom, const std::vector<Id>& env) const
{
  std::string s = "(" + predicates_[atom.predicate].name;
  for(const Term& t : atom.args)
  {
    s += " " + showTerm(t, env);
  }
  return s + ")";
}

std::string World::whyNot(const State& s, const Formula& f, std::vector<Id>& env) const
{
  switch(f.kind)
  {
    case Formula::Kind::Atom:
      return "`" + showGround(f, env) + "` is false";
    case Formula::Kind::Equal:
      return "`" + showTerm(f.args[0], env) + "` and `" + showTerm(f.args[1], env) +
             "` are different objects";
    case Formula::Kind::Not: {
      const Formula& inner = f.parts[0];
      if(inner.kind == Formula::Kind::Atom)
      {
        return "`" + showGround(inner, env) + "` is true, but must be false";
      }
      if(inner.kind == Formula::Kind::Equal)
      {
        return "`" + showTerm(inner.args[0], env) + "` and `" + showTerm(inner.args[1], env) +
               "` are the same object, but must differ";
      }
      return "a negated condition holds";
    }
    case Formula::Kind::And:
      for(const Formula& p : f.parts)
      {
        if(!holds(s, p, env))
        {
          return whyNot(s, p, env);
        }
      }
      return "";
    case Formula::Kind::Or:
      return "none of the alternatives of an `or` holds";
    case Formula::Kind::Imply:
      return "the condition of an `imply` holds, but " + whyNot(s, f.parts[1], env);
    case Formula::Kind::Exists: {
      std::string vs;
      for(const QVar& v : f.vars)
      {
        vs += (vs.empty() ? "?" : " ?") + v.name;
      }
      return "no choice of " + vs + " satisfies an `exists`";
    }
    case Formula::Kind::Forall: {
      std::string why;
      eachBinding(f.vars, 0, env, [&] {
        if(holds(s, f.parts[0], env))
        {
          return false;
        }
        std::string bound;
        for(const QVar& v : f.vars)
        {
          bound += (bound.empty() ? "?" : ", ?") + v.name + " = " + object_names_[env[v.slot]];
        }
        why = "for " + bound + ": " + whyNot(s, f.parts[0], env);
        return true;
      });
      return why;
    }
    default:
      return "a numeric comparison does not hold";
  }
}

// --------------------------------------------------------- the .kb file

World World::read(const Sexp& kb, const std::string& origin, State& initial)
{
  World w;
  auto bad = [&](const std::string& msg) -> KbError {
    return KbError(origin + ": " + msg);
  };
  const std::string* h = kb.head();
  if(h == nullptr || *h != "kb" || kb.items.size() < 2 ||
     kb.items[1].kind != Sexp::Kind::Number)
  {
    throw bad("this is not a btc KB file (it starts with `(kb 1`; write one with "
              "`btc compile RULES --plan PLAN --emit kb`)");
  }
  if(kb.items[1].number != 1)
  {
    throw bad("KB file version " + kb.items[1].text + ": this library reads version 1");
  }
  std::map<std::string, const Sexp*> sections;
  for(std::size_t i = 2; i < kb.items.size(); ++i)
  {
    const Sexp& sec = kb.items[i];
    if(!sec.isList() || sec.items.empty() || sec.items[0].kind != Sexp::Kind::Keyword)
    {
      throw bad("`" + sec.show() + "` is not a section such as `(:objects ...)`");
    }
    sections[sec.items[0].text] = &sec;
  }
  auto section = [&](const char* name) -> const std::vector<Sexp>& {
    static const std::vector<Sexp> none;
    auto it = sections.find(name);
    return it == sections.end() ? none : it->second->items;
  };
  auto name1 = [&](const char* name) -> std::string {
    const auto& items = section(name);
    return items.size() == 2 ? items[1].text : std::string();
  };
  w.domain = name1("domain");
  w.problem = name1("problem");
  try
  {
    const auto& types = section("types");
    for(std::size_t i = 1; i < types.size(); ++i)
    {
      const Sexp& t = types[i];
      if(!t.isList() || t.items.empty() || t.items[0].kind != Sexp::Kind::Name)
      {
        fail("`" + t.show() + "` is not a type with its ancestors");
      }
      w.type_ids_[t.items[0].text] = static_cast<Id>(w.type_names_.size());
      w.type_names_.push_back(t.items[0].text);
    }
    if(w.type_ids_.count("object") == 0)
    {
      w.type_ids_["object"] = static_cast<Id>(w.type_names_.size());
      w.type_names_.push_back("object");
    }
    w.object_type_ = w.type_ids_.at("object");
    w.ancestors_.resize(w.type_names_.size());
    for(std::size_t i = 1; i < types.size(); ++i)
    {
      const Id id = w.type_ids_.at(types[i].items[0].text);
      w.ancestors_[id].push_back(id);
      for(std::size_t j = 1; j < types[i].items.size(); ++j)
      {
        const auto t = w.typeSpec(types[i].items[j]);
        w.ancestors_[id].insert(w.ancestors_[id].end(), t.begin(), t.end());
      }
    }
    const auto& objects = section("objects");
    for(std::size_t i = 1; i < objects.size(); ++i)
    {
      const Sexp& o = objects[i];
      if(!o.isList() || o.items.size() < 2 || o.items[0].kind != Sexp::Kind::Name)
      {
        fail("`" + o.show() + "` is not an object with its types");
      }
      w.object_ids_[o.items[0].text] = static_cast<Id>(w.object_names_.size());
      w.object_names_.push_back(o.items[0].text);
      std::vector<Id> ts;
      for(std::size_t j = 1; j < o.items.size(); ++j)
      {
        const auto t = w.typeSpec(o.items[j]);
        ts.insert(ts.end(), t.begin(), t.end());
      }
      w.object_types_.push_back(std::move(ts));
    }
    auto signatures = [&](const char* name, std::vector<Signature>& out,
                          std::unordered_map<std::string, Id>& ids) {
      const auto& items = section(name);
      for(std::size_t i = 1; i < items.size(); ++i)
      {
        const Sexp& d = items[i];
        if(!d.isList() || d.items.empty() || d.items[0].kind != Sexp::Kind::Name)
        {
          fail("`" + d.show() + "` is not a name with its parameter types");
        }
        Signature sig;
        sig.name = d.items[0].text;
        for(std::size_t j = 1; j < d.items.size(); ++j)
        {
          sig.params.push_back(w.typeSpec(d.items[j]));
        }
        ids[sig.name] = static_cast<Id>(out.size());
        out.push_back(std::move(sig));
      }
    };
    signatures("predicates", w.predicates_, w.predicate_ids_);
    signatures("functions", w.functions_, w.function_ids_);
    // Heads first: a rule's body may use any derived predicate.
    const auto& derived = section("derived");
    auto rules_of = [&](const Sexp& stratum) {
      if(!stratum.isList() || stratum.items.empty() || stratum.items[0].kind != Sexp::Kind::Keyword ||
         stratum.items[0].text != "stratum")
      {
        fail("`" + stratum.show() + "` is not a `(:stratum ...)`");
      }
      return &stratum.items;
    };
    for(std::size_t i = 1; i < derived.size(); ++i)
    {
      const auto& rules = *rules_of(derived[i]);
      for(std::size_t j = 1; j < rules.size(); ++j)
      {
        const Sexp& r = rules[j];
        if(r.items.size() != 3 || !r.items[1].isList() || r.items[1].head() == nullptr)
        {
          fail("`" + r.show() + "` is not a `(:rule (head ?x - t) body)`");
        }
        auto it = w.predicate_ids_.find(*r.items[1].head());
        if(it == w.predicate_ids_.end())
        {
          fail("`" + *r.items[1].head() + "` is not a predicate of domain " + w.domain);
        }
        w.predicates_[it->second].derived = true;
      }
    }
    for(std::size_t i = 1; i < derived.size(); ++i)
    {
      const auto& rules = *rules_of(derived[i]);
      std::vector<DerivedRule> stratum;
      for(std::size_t j = 1; j < rules.size(); ++j)
      {
        const Sexp& head = rules[j].items[1];
        DerivedRule rule;
        rule.predicate = w.predicate_ids_.at(*head.head());
        Sexp params = head;
        params.items.erase(params.items.begin());
        Scope scope;
        rule.params = w.typedVars(params, scope);
        if(rule.params.size() != w.predicates_[rule.predicate].params.size())
        {
          fail("the rule for `" + *head.head() + "` has the wrong number of parameters");
        }
        rule.body = w.formula(rules[j].items[2], scope);
        stratum.push_back(std::move(rule));
      }
      w.strata_.push_back(std::move(stratum));
    }
    const auto& init = section("init");
    std::vector<Id> env;
    Scope none;
    for(std::size_t i = 1; i < init.size(); ++i)
    {
      const Sexp& f = init[i];
      const std::string* fh = f.head();
      if(fh != nullptr && *fh == "=" && f.items.size() == 3 && f.items[1].isList() &&
         f.items[2].kind == Sexp::Kind::Number)
      {
        const Sexp& fl = f.items[1];
        const std::string* flh = fl.head();
        auto it = flh ? w.function_ids_.find(*flh) : w.function_ids_.end();
        if(it == w.function_ids_.end())
        {
          fail("`" + fl.show() + "` is not a function of domain " + w.domain);
        }
        Key k;
        w.key(it->second, w.args(fl, w.functions_[it->second], none, "function"), env, k);
        initial.fluents[k] = f.items[2].number;
        continue;
      }
      auto it = fh ? w.predicate_ids_.find(*fh) : w.predicate_ids_.end();
      if(it == w.predicate_ids_.end())
      {
        fail("`" + f.show() + "` is not a fact of domain " + w.domain);
      }
      Key k;
      w.key(it->second, w.args(f, w.predicates_[it->second], none, "predicate"), env, k);
      initial.facts.insert(std::move(k));
    }
    const auto& goal = section("goal");
    if(goal.size() == 2)
    {
      w.goal_ = w.compileFormula(goal[1]);
    }
  }
  catch(const KbError& e)
  {
    throw bad(e.what());
  }
  w.closeDerived(initial);
  return w;
}

}  // namespace btc::detail
