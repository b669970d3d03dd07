// btc's knowledge base for BehaviorTree.CPP: the ground facts and numeric
// fluents of a PDDL problem, the formulas and effects a compiled tree carries
// (as PDDL text in its XML attributes) evaluated and applied on them, and
// the progress of the plan's steps.
//
// The world comes from a `.kb` file that `btc compile ... --emit kb` writes
// (the problem's objects with their types, the initial state, the derived
// predicates, the goal), so this library never reads a PDDL domain. The
// semantics are btc's (`btc_pddl::state`): the same formulas hold, the same
// effects make the same changes, in the same order.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace btc
{

/// What the knowledge base refuses: a `.kb` file it cannot read, a formula
/// or effect that is not PDDL or does not fit the problem.
class KbError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// A formula or effect parsed and checked once ([`Kb::formula`]).
using FormulaId = std::uint32_t;
using EffectId = std::uint32_t;

/// A plan step as the tree's `KbStep` nodes describe it.
struct Step
{
  int number = 0;  ///< 1-based, as in the XML's `step` attribute
  std::string label;  ///< `step 2: (grasp floor_robot battery_red bin1)`
  std::optional<FormulaId> start_condition;
  std::optional<FormulaId> over_all_condition;
  std::optional<FormulaId> end_condition;
  std::optional<EffectId> start_effect;
  std::optional<EffectId> end_effect;
  bool declared = false;  ///< some `KbStep` names it (others count as skipped)
  bool started = false;
  bool finished = false;

  /// What an action leaf of the step checks when it starts: the
  /// precondition, or (when at-start effects already changed the KB) the
  /// over-all condition.
  std::optional<FormulaId> leafCheck() const;
};

/// A step starting or finishing, for loggers and the executor's trace.
struct StepEvent
{
  enum class Kind
  {
    Started,
    Finished
  };
  Kind kind;
  int step;
};

/// A fault a node reports (`Kb::reportFault`): one of ARIAC 2023's fault
/// kinds, what it names, and how it changes the KB (at once: see
/// `Kb::reportFault`). The closed loop (`btc::Agent`) replans from the
/// state the fault left and adjusts the goal as `btc run --replan` does: a
/// spare part for a discarded one (`faulty_part`, `flipped_part` with a
/// `part`), a priority order's `goal` first (`high_priority_order`).
struct ReportedFault
{
  /// faulty_part, faulty_gripper, robot_malfunction, flipped_part,
  /// sensor_blackout, high_priority_order, insufficient_parts,
  /// human_too_close.
  std::string kind;
  std::optional<std::string> part;
  std::optional<std::string> robot;
  /// A priority order's goal, PDDL text.
  std::optional<std::string> goal;
  /// Facts no longer true, and facts now true, as PDDL atoms.
  std::vector<std::string> retract;
  std::vector<std::string> add;
  /// What the node saw, in words (the fault record's reason).
  std::string reason;
  /// Its label in btc's report (empty: the kind).
  std::string name;
  /// How long it lasts, in ticks (a malfunction, a blackout, a human).
  std::optional<long> duration;
  /// The tick of the attempt it happened at (the agent sets it).
  long tick = 0;
};

/// The knowledge base: shared by every node of a tree (`registerKbNodes`
/// passes it to the nodes' constructors) and by the user's own nodes.
/// Not thread-safe: use it from the thread that ticks the tree.
class Kb
{
public:
  /// Reads a `.kb` file; throws `KbError` naming the file and the place.
  static Kb fromFile(const std::string& path);
  /// Reads `.kb` text; `origin` names it in errors.
  static Kb fromText(const std::string& text, const std::string& origin = "<kb>");

  Kb(Kb&&) noexcept;
  Kb& operator=(Kb&&) noexcept;
  ~Kb();

  const std::string& domainName() const;
  const std::string& problemName() const;

  /// Parses and checks a ground PDDL condition, e.g. `(on battery_red bin1)`
  /// (cached by its text). Throws `KbError` when it is not PDDL or does not
  /// fit the problem (an unknown predicate, object, arity, type).
  FormulaId formula(const std::string& text);
  /// Parses and checks a ground PDDL effect, e.g. `(and (a) (not (b)))`.
  EffectId effect(const std::string& text);

  bool holds(FormulaId f) const;
  /// `formula(text)` then `holds`.
  bool holds(const std::string& text);
  /// Why `f` does not hold, in PDDL terms: the first false literal.
  std::string whyNot(FormulaId f) const;

  /// Applies an effect: its changes are computed in the current state,
  /// then deletes, adds and numeric updates happen; derived predicates are
  /// recomputed.
  void apply(EffectId e);
  void apply(const std::string& text);

  /// A fluent's value, e.g. `value("(total-cost)")`; empty when undefined.
  std::optional<double> value(const std::string& fluent_text);

  /// True facts and fluent values (`(= (f a) 2.0)`), sorted: what btc's
  /// fault records and `btc run` show as the KB.
  std::vector<std::string> snapshot() const;

  /// Whether the problem's goal holds (true when it has none).
  bool goalHolds() const;
  /// Why the goal does not hold; empty when it does.
  std::string goalFailure() const;

  // --- The plan's steps, as `KbStep` nodes declare and run them.

  /// The step numbered `number` (1-based), created when needed.
  Step& declareStep(int number);
  /// The step numbered `number`, or null when no `KbStep` goes that far.
  Step* step(int number);
  /// The highest step number a `KbStep` declared.
  int stepCount() const;
  /// The innermost step being ticked (0 outside every step): `KbStep`
  /// enters it around its child's tick, so a leaf knows its step.
  int currentStep() const;
  void enterStep(int number);
  void leaveStep();
  /// Tells the listeners that a step started or finished (`KbStep` does,
  /// each time it starts, and once when the step is done).
  void stepEvent(StepEvent::Kind kind, int number);
  /// Called on every step start and end.
  void onStepEvent(std::function<void(const StepEvent&)> listener);

  /// The last failure a KB node or a simulated leaf explained (its node
  /// name and why), for the executor's summary.
  void noteFailure(const std::string& node, const std::string& why);
  const std::string& lastFailure() const;
  /// The why of `lastFailure()` alone.
  const std::string& lastFailureWhy() const;

  // --- Between runs: the closed loop sets the state each attempt starts
  // from, and collects the faults its nodes reported.

  /// Replaces the state with these facts and values (`(at r1 a)`,
  /// `(= (battery r1) 20.0)`, as `snapshot()` writes them); derived
  /// predicates are recomputed. Throws `KbError` for a fact that does not
  /// fit the problem.
  void setState(const std::vector<std::string>& facts);
  /// Replaces the goal (PDDL text).
  void setGoal(const std::string& goal);
  /// Forgets the plan's steps and the last failure: the next tree declares
  /// its own.
  void resetSteps();

  /// Reports a fault: from a node that then returns FAILURE, or from
  /// outside the tree between ticks (`Agent::before_tick`: an order
  /// arrives, a part is found missing). Its changes apply now, as btc's
  /// engine applies a scenario's fault: the `retract` facts become false
  /// and the `add` facts true; a `faulty_part` or `insufficient_parts`
  /// without `retract` takes every fact that names its `part` (it is
  /// gone). A fact that does not fit the problem changes nothing here; the
  /// loop refuses the report when the attempt ends.
  void reportFault(ReportedFault fault);
  /// The faults reported since the last call, which forgets them.
  std::vector<ReportedFault> takeFaults();

  /// What the KB's conditions (conditions defined by a formula, `KbHolds`)
  /// return while the sensors they stand in for send nothing, as in a
  /// sensor blackout of btc's engine: RUNNING, or FAILURE. `None`, the
  /// default: they evaluate their formula. Whoever knows of the blackout
  /// (perception, `Agent::before_tick`) sets it and sets it back.
  enum class Blackout
  {
    None,
    Running,
    Failure
  };
  void setBlackout(Blackout b);
  Blackout blackout() const;

  /// How long simulated action leaves run: RUNNING for this many ticks,
  /// then SUCCESS (0: they succeed at once). `btc run --ticks-per-action`.
  int ticks_per_action = 1;

private:
  struct Impl;
  explicit Kb(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> p_;
};

/// A number as btc prints it: whole numbers with one decimal (`3.0`),
/// others in the shortest form that reads back the same (`0.1`).
std::string formatNumber(double x);

/// Replaces the `?name` variables of PDDL text with `value(name)` (names
/// lower-cased; a `?a` never touches `?ab`); a variable for which `value`
/// returns nothing stays as it is.
std::string substitute(const std::string& text,
                       const std::function<std::optional<std::string>(const std::string&)>& value);

}  // namespace btc
