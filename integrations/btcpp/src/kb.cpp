#include "btc/kb.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "world.hpp"

namespace btc
{

using detail::Changes;
using detail::Effect;
using detail::Formula;
using detail::Id;
using detail::State;
using detail::World;

struct Kb::Impl
{
  World world;
  State state;
  std::vector<Formula> formulas;
  std::vector<Effect> effects;
  std::unordered_map<std::string, FormulaId> formula_ids;
  std::unordered_map<std::string, EffectId> effect_ids;
  mutable std::vector<Id> env;
  std::vector<Step> steps;  // index: number - 1
  std::vector<int> current;
  std::vector<std::function<void(const StepEvent&)>> listeners;
  std::string last_failure;
  std::string last_failure_why;
  std::vector<ReportedFault> faults;
  Kb::Blackout blackout = Kb::Blackout::None;

  std::vector<Id>& scratch() const
  {
    if(env.size() < world.slots())
    {
      env.resize(world.slots());
    }
    return env;
  }
};

std::optional<FormulaId> Step::leafCheck() const
{
  if(start_effect)
  {
    return over_all_condition;
  }
  return start_condition ? start_condition : over_all_condition;
}

Kb::Kb(std::unique_ptr<Impl> impl) : p_(std::move(impl)) {}
Kb::Kb(Kb&&) noexcept = default;
Kb& Kb::operator=(Kb&&) noexcept = default;
Kb::~Kb() = default;

Kb Kb::fromText(const std::string& text, const std::string& origin)
{
  auto forest = detail::readSexps(text, origin);
  if(forest.size() != 1)
  {
    throw KbError(origin + ": a KB file is one `(kb 1 ...)` expression, found " +
                  std::to_string(forest.size()));
  }
  auto impl = std::make_unique<Impl>();
  impl->world = World::read(forest[0], origin, impl->state);
  return Kb(std::move(impl));
}

Kb Kb::fromFile(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if(!in)
  {
    throw KbError(path + ": cannot read this file");
  }
  std::ostringstream text;
  text << in.rdbuf();
  return fromText(text.str(), path);
}

const std::string& Kb::domainName() const
{
  return p_->world.domain;
}

const std::string& Kb::problemName() const
{
  return p_->world.problem;
}

FormulaId Kb::formula(const std::string& text)
{
  auto it = p_->formula_ids.find(text);
  if(it != p_->formula_ids.end())
  {
    return it->second;
  }
  try
  {
    const auto s = detail::readOne(text, "condition");
    p_->formulas.push_back(p_->world.compileFormula(s));
  }
  catch(const KbError& e)
  {
    throw KbError("`" + text + "` is not a condition of problem " + p_->world.problem + ": " +
                  e.what());
  }
  const auto id = static_cast<FormulaId>(p_->formulas.size() - 1);
  p_->formula_ids.emplace(text, id);
  return id;
}

EffectId Kb::effect(const std::string& text)
{
  auto it = p_->effect_ids.find(text);
  if(it != p_->effect_ids.end())
  {
    return it->second;
  }
  try
  {
    const auto s = detail::readOne(text, "effect");
    p_->effects.push_back(p_->world.compileEffect(s));
  }
  catch(const KbError& e)
  {
    throw KbError("`" + text + "` is not an effect of problem " + p_->world.problem + ": " +
                  e.what());
  }
  const auto id = static_cast<EffectId>(p_->effects.size() - 1);
  p_->effect_ids.emplace(text, id);
  return id;
}

bool Kb::holds(FormulaId f) const
{
  return p_->world.holds(p_->state, p_->formulas.at(f), p_->scratch());
}

bool Kb::holds(const std::string& text)
{
  return holds(formula(text));
}

std::string Kb::whyNot(FormulaId f) const
{
  return p_->world.whyNot(p_->state, p_->formulas.at(f), p_->scratch());
}

void Kb::apply(EffectId e)
{
  Changes c;
  p_->world.collect(p_->state, p_->effects.at(e), p_->scratch(), c);
  p_->world.apply(p_->state, std::move(c));
}

void Kb::apply(const std::string& text)
{
  apply(effect(text));
}

std::optional<double> Kb::value(const std::string& fluent_text)
{
  // A fluent is read through a comparison with itself: the same parser
  // and checks as every other formula.
  const FormulaId f = formula("(= " + fluent_text + " " + fluent_text + ")");
  const Formula& cmp = p_->formulas[f];
  return p_->world.value(p_->state, *cmp.left, p_->scratch());
}

std::vector<std::string> Kb::snapshot() const
{
  std::vector<std::string> out;
  out.reserve(p_->state.facts.size() + p_->state.fluents.size());
  for(const auto& k : p_->state.facts)
  {
    out.push_back(p_->world.showAtom(k));
  }
  for(const auto& [k, v] : p_->state.fluents)
  {
    out.push_back("(= " + p_->world.showFluent(k) + " " + formatNumber(v) + ")");
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool Kb::goalHolds() const
{
  const Formula* g = p_->world.goal();
  return g == nullptr || p_->world.holds(p_->state, *g, p_->scratch());
}

std::string Kb::goalFailure() const
{
  const Formula* g = p_->world.goal();
  if(g == nullptr || goalHolds())
  {
    return "";
  }
  return p_->world.whyNot(p_->state, *g, p_->scratch());
}

// ------------------------------------------------------------------ steps

Step& Kb::declareStep(int number)
{
  if(number < 1)
  {
    throw KbError("step numbers count from 1, not " + std::to_string(number));
  }
  while(static_cast<int>(p_->steps.size()) < number)
  {
    Step s;
    s.number = static_cast<int>(p_->steps.size()) + 1;
    s.label = "step " + std::to_string(s.number);
    p_->steps.push_back(std::move(s));
  }
  Step& s = p_->steps[static_cast<std::size_t>(number - 1)];
  s.declared = true;
  return s;
}

Step* Kb::step(int number)
{
  if(number < 1 || number > static_cast<int>(p_->steps.size()))
  {
    return nullptr;
  }
  return &p_->steps[static_cast<std::size_t>(number - 1)];
}

int Kb::stepCount() const
{
  return static_cast<int>(p_->steps.size());
}

int Kb::currentStep() const
{
  return p_->current.empty() ? 0 : p_->current.back();
}

void Kb::enterStep(int number)
{
  p_->current.push_back(number);
}

void Kb::leaveStep()
{
  if(!p_->current.empty())
  {
    p_->current.pop_back();
  }
}

void Kb::stepEvent(StepEvent::Kind kind, int number)
{
  for(const auto& l : p_->listeners)
  {
    l(StepEvent{ kind, number });
  }
}

void Kb::onStepEvent(std::function<void(const StepEvent&)> listener)
{
  p_->listeners.push_back(std::move(listener));
}

void Kb::noteFailure(const std::string& node, const std::string& why)
{
  p_->last_failure = node + ": " + why;
  p_->last_failure_why = why;
}

const std::string& Kb::lastFailureWhy() const
{
  return p_->last_failure_why;
}

const std::string& Kb::lastFailure() const
{
  return p_->last_failure;
}

// ------------------------------------------------------------------ between runs

void Kb::setState(const std::vector<std::string>& facts)
{
  // The facts become one effect applied to an empty state: the same
  // parser and checks as every effect, values through `assign`.
  std::string effect = "(and";
  for(const auto& f : facts)
  {
    const auto s = detail::readOne(f, "fact");
    const bool value = s.isList() && s.items.size() == 3 && s.items[0].isName("=");
    effect += value ? " (assign " + s.items[1].show() + " " + s.items[2].show() + ")" : " " + f;
  }
  effect += ")";
  Effect e;
  try
  {
    e = p_->world.compileEffect(detail::readOne(effect, "state"));
  }
  catch(const KbError& err)
  {
    throw KbError("a state that does not fit problem " + p_->world.problem + ": " + err.what());
  }
  State fresh;
  Changes c;
  p_->world.collect(fresh, e, p_->scratch(), c);
  p_->world.apply(fresh, std::move(c));
  p_->state = std::move(fresh);
}

void Kb::setGoal(const std::string& goal)
{
  try
  {
    p_->world.setGoal(p_->world.compileFormula(detail::readOne(goal, "goal")));
  }
  catch(const KbError& err)
  {
    throw KbError("`" + goal + "` is not a goal of problem " + p_->world.problem + ": " +
                  err.what());
  }
}

void Kb::resetSteps()
{
  p_->steps.clear();
  p_->current.clear();
  p_->last_failure.clear();
  p_->last_failure_why.clear();
}

namespace
{

/// Whether a shown atom, `(p a b)`, has `object` among its arguments.
bool mentions(const std::string& atom, const std::string& object)
{
  std::size_t at = atom.find(' ');
  while(at != std::string::npos)
  {
    const std::size_t from = at + 1;
    at = atom.find(' ', from);
    const std::size_t end = at == std::string::npos ? atom.size() - 1 : at;
    if(atom.compare(from, end - from, object) == 0 && end - from == object.size())
    {
      return true;
    }
  }
  return false;
}

}  // namespace

void Kb::reportFault(ReportedFault fault)
{
  // The changes apply now, as btc's engine applies a scenario's fault when
  // it happens (`FaultSpec::changes`): the rest of the tick and the ticks
  // after it see the world the fault left.
  std::vector<std::string> retract = fault.retract;
  const bool gone = fault.kind == "faulty_part" || fault.kind == "insufficient_parts";
  if(retract.empty() && fault.part && gone)
  {
    for(const auto& k : p_->state.facts)
    {
      std::string atom = p_->world.showAtom(k);
      if(mentions(atom, *fault.part))
      {
        retract.push_back(std::move(atom));
      }
    }
  }
  if(!retract.empty() || !fault.add.empty())
  {
    std::string text = "(and";
    for(const auto& r : retract)
    {
      text += " (not " + r + ")";
    }
    for(const auto& a : fault.add)
    {
      text += " " + a;
    }
    text += ")";
    try
    {
      apply(text);
    }
    catch(const KbError&)
    {
      // A fact that does not fit the problem: the loop refuses the report
      // when the attempt ends, with a diagnostic naming the fault and the
      // fact, which is the error the caller gets.
    }
  }
  p_->faults.push_back(std::move(fault));
}

void Kb::setBlackout(Blackout b)
{
  p_->blackout = b;
}

Kb::Blackout Kb::blackout() const
{
  return p_->blackout;
}

std::vector<ReportedFault> Kb::takeFaults()
{
  return std::exchange(p_->faults, {});
}

// ------------------------------------------------------------------ text

std::string formatNumber(double x)
{
  if(std::isnan(x))
  {
    return "NaN";
  }
  if(std::isinf(x))
  {
    return x > 0 ? "inf" : "-inf";
  }
  char buf[512];
  if(std::floor(x) == x && std::fabs(x) < 1e15)
  {
    auto r = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::fixed, 1);
    return std::string(buf, r.ptr);
  }
  // Shortest digits that read back the same, never in exponent form: what
  // Rust's `{}` prints for an f64.
  auto r = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::fixed);
  return std::string(buf, r.ptr);
}

std::string substitute(const std::string& text,
                       const std::function<std::optional<std::string>(const std::string&)>& value)
{
  std::string out;
  out.reserve(text.size() + 16);
  std::size_t i = 0;
  while(i < text.size())
  {
    const char c = text[i];
    if(c != '?')
    {
      out += c;
      ++i;
      continue;
    }
    std::size_t j = i + 1;
    while(j < text.size())
    {
      const auto d = static_cast<unsigned char>(text[j]);
      const bool word = (d >= 'a' && d <= 'z') || (d >= 'A' && d <= 'Z') ||
                        (d >= '0' && d <= '9') || d == '_' || d == '-' || d >= 0x80;
      if(!word)
      {
        break;
      }
      ++j;
    }
    std::string var = text.substr(i + 1, j - i - 1);
    std::string key = var;
    for(auto& ch : key)
    {
      if(ch >= 'A' && ch <= 'Z')
      {
        ch = static_cast<char>(ch - 'A' + 'a');
      }
    }
    std::optional<std::string> v;
    if(!var.empty())
    {
      v = value(key);
    }
    if(v)
    {
      out += *v;
    }
    else
    {
      out += '?';
      out += var;
    }
    i = j;
  }
  return out;
}

}  // namespace btc
