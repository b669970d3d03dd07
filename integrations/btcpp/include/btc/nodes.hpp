// The nodes btc's trees need in BehaviorTree.CPP: the plan step decorator
// `KbStep`, the `std::kb` leaves `KbHolds`, `KbApply` and `WaitForStep`,
// conditions defined by a PDDL formula, and a base for action leaves whose
// default body simulates the action as `btc run` does. They behave exactly
// as btc's engine runs them (runtime/src/engine.rs).
//
// Every node is handed the shared `btc::Kb` through its constructor; so are
// the user's own nodes (see docs/btcpp.md):
//
//   btc::Kb kb = btc::Kb::fromFile("world.kb");
//   BT::BehaviorTreeFactory factory;
//   btc::registerKbNodes(factory, kb);
//   factory.registerNodeType<MyGrasp>("Grasp", std::ref(kb));
#pragma once

#include <behaviortree_cpp/bt_factory.h>

#include <string>
#include <vector>

#include "btc/kb.hpp"

namespace btc
{

/// A port's type as a rules file declares it: PDDL objects and `string`
/// are `std::string`, `int` is `int`, `float` is `double`, `bool` is `bool`.
enum class PortType
{
  String,
  Int,
  Double,
  Bool
};

struct PortSpec
{
  std::string name;
  PortType type = PortType::String;
  std::string description;
};

/// A condition of a rules file: `condition ID(ports) = FORMULA`. The
/// formula's `?port` variables take the ports' values at every tick.
struct ConditionSpec
{
  std::string id;
  std::string formula;
  std::vector<PortSpec> ports;
};

/// BT.CPP input ports for `ports`, typed as declared.
BT::PortsList inputPorts(const std::vector<PortSpec>& ports);

/// The text of a port's current value (what replaces `?port` in a
/// formula): strings as they are, numbers as btc prints them, `true` or
/// `false`. Empty when the port is not set.
std::optional<std::string> portText(const BT::TreeNode& node, const PortSpec& port);

/// An input port's value; throws `BT::RuntimeError` naming the node and
/// the port when it is missing or does not convert to `T`.
template <class T>
T input(const BT::TreeNode& node, const std::string& port)
{
  auto v = node.getInput<T>(port);
  if(!v)
  {
    throw BT::RuntimeError(node.registrationName(), " `", node.name(), "`: port `", port,
                           "`: ", v.error());
  }
  return v.value();
}

/// Writes an output port; throws `BT::RuntimeError` when it cannot.
template <class T>
void output(BT::TreeNode& node, const std::string& port, const T& value)
{
  auto r = node.setOutput<T>(port, value);
  if(!r)
  {
    throw BT::RuntimeError(node.registrationName(), " `", node.name(), "`: port `", port,
                           "`: ", r.error());
  }
}

/// A plan step: applies its at-start effects when it starts (after
/// checking its precondition, if it has such effects), its at-end effects
/// when its child succeeds (after checking its at-end condition), and tells
/// the KB's listeners. Leaves below it know it as `Kb::currentStep()`.
class KbStep : public BT::DecoratorNode
{
public:
  KbStep(const std::string& name, const BT::NodeConfig& config, Kb& kb);
  static BT::PortsList providedPorts();

private:
  BT::NodeStatus tick() override;
  Kb& kb_;
  int number_ = 0;
};

/// SUCCESS when a ground formula holds on the KB, else FAILURE (in a
/// sensor blackout, what `Kb::blackout()` says).
class KbHolds : public BT::ConditionNode
{
public:
  KbHolds(const std::string& name, const BT::NodeConfig& config, Kb& kb);
  static BT::PortsList providedPorts();

private:
  BT::NodeStatus tick() override;
  Kb& kb_;
  std::optional<FormulaId> formula_;
};

/// Applies a ground effect to the KB; SUCCESS.
class KbApply : public BT::SyncActionNode
{
public:
  KbApply(const std::string& name, const BT::NodeConfig& config, Kb& kb);
  static BT::PortsList providedPorts();

private:
  BT::NodeStatus tick() override;
  Kb& kb_;
  std::optional<EffectId> effect_;
};

/// RUNNING until plan step `step` is done (or is one the tree skips);
/// FAILURE when the plan has no such step. `steps parallel` uses it.
class WaitForStep : public BT::ActionNodeBase
{
public:
  WaitForStep(const std::string& name, const BT::NodeConfig& config, Kb& kb);
  static BT::PortsList providedPorts();

private:
  BT::NodeStatus tick() override;
  void halt() override {}
  Kb& kb_;
  int step_ = 0;
};

/// A condition leaf. With a formula, SUCCESS when the formula, with the
/// ports' values for its variables, holds on the KB at this tick (in a
/// sensor blackout, what `Kb::blackout()` says); without one, SUCCESS.
/// Derive from it (or from the generated base) and override `tick()` to
/// read a real sensor instead.
class Condition : public BT::ConditionNode
{
public:
  Condition(const std::string& name, const BT::NodeConfig& config, Kb& kb,
            std::string formula, std::vector<PortSpec> ports);

protected:
  BT::NodeStatus tick() override;
  /// The formula with the ports' current values filled in.
  std::string groundFormula() const;
  Kb& kb() const { return kb_; }

private:
  Kb& kb_;
  std::string formula_;
  std::vector<PortSpec> ports_;
};

/// A base for action leaves, with BT.CPP's StatefulActionNode protocol:
/// `onStart()` on the first tick, `onRunning()` while RUNNING, `onHalted()`
/// when halted. The default bodies simulate the action as `btc run` does:
/// the step's precondition is checked when the action starts (FAILURE if
/// it does not hold), then it stays RUNNING for `Kb::ticks_per_action`
/// ticks and succeeds. (Unlike StatefulActionNode, a finished action ticked
/// again starts again, as in btc's engine.)
class Action : public BT::ActionNodeBase
{
public:
  Action(const std::string& name, const BT::NodeConfig& config, Kb& kb);

protected:
  virtual BT::NodeStatus onStart();
  virtual BT::NodeStatus onRunning();
  virtual void onHalted() {}

  Kb& kb() const { return kb_; }
  /// The plan step this action runs in, or null outside every step.
  Step* step() const;
  /// Whether the step's precondition holds (true outside every step);
  /// when it does not, the KB notes why, in the words of btc's engine, for
  /// the fault record. The default `onStart()` checks it; an `onStart()`
  /// of yours that sends a goal checks it first, as btc's engine does.
  bool preconditionHolds();
  /// An input port's value (see `btc::input`).
  template <class T>
  T input(const std::string& port) const
  {
    return btc::input<T>(*this, port);
  }

private:
  BT::NodeStatus tick() final;
  void halt() final;
  Kb& kb_;
  int remaining_ = 0;
};

/// Registers `KbStep`, `KbHolds`, `KbApply`, `WaitForStep`, and one
/// `Condition` per entry of `conditions`, all sharing `kb` (which must
/// outlive every tree the factory makes).
void registerKbNodes(BT::BehaviorTreeFactory& factory, Kb& kb,
                     const std::vector<ConditionSpec>& conditions = {});

/// Registers a simulated `Action` for each ID (with these ports): enough
/// to run a compiled tree before writing real nodes.
void registerSimulatedAction(BT::BehaviorTreeFactory& factory, Kb& kb, const std::string& id,
                             const std::vector<PortSpec>& ports);

}  // namespace btc
