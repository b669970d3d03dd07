#include "btc/nodes.hpp"

#include <functional>

namespace btc
{

using BT::NodeStatus;

namespace
{

/// An attribute written out in the XML (KB nodes take no blackboard
/// entries: their texts are compiled when the tree is made).
std::optional<std::string> literal(const BT::NodeConfig& config, const std::string& node,
                                   const std::string& port, bool required)
{
  auto it = config.input_ports.find(port);
  if(it == config.input_ports.end())
  {
    if(required)
    {
      throw BT::RuntimeError("`", node, "` needs the port `", port, "`");
    }
    return std::nullopt;
  }
  const std::string& v = it->second;
  if(v.size() >= 2 && v.front() == '{' && v.back() == '}')
  {
    throw BT::RuntimeError("port `", port, "` of `", node,
                           "` must be written out, not read from the blackboard entry ", v);
  }
  return v;
}

bool blank(const std::string& s)
{
  return s.find_first_not_of(" \t\r\n") == std::string::npos;
}

/// Compiles an optional formula or effect attribute, naming the node when
/// the KB refuses it.
template <class F>
auto compiled(const std::optional<std::string>& text, const std::string& node, F&& f)
    -> std::optional<decltype(f(std::string()))>
{
  if(!text || blank(*text))
  {
    return std::nullopt;
  }
  try
  {
    return f(*text);
  }
  catch(const KbError& e)
  {
    throw BT::RuntimeError("`", node, "`: ", e.what());
  }
}

}  // namespace

BT::PortsList inputPorts(const std::vector<PortSpec>& ports)
{
  BT::PortsList out;
  for(const auto& p : ports)
  {
    switch(p.type)
    {
      case PortType::Int:
        out.insert(BT::InputPort<int>(p.name, p.description));
        break;
      case PortType::Double:
        out.insert(BT::InputPort<double>(p.name, p.description));
        break;
      case PortType::Bool:
        out.insert(BT::InputPort<bool>(p.name, p.description));
        break;
      default:
        out.insert(BT::InputPort<std::string>(p.name, p.description));
        break;
    }
  }
  return out;
}

std::optional<std::string> portText(const BT::TreeNode& node, const PortSpec& port)
{
  switch(port.type)
  {
    case PortType::Int: {
      auto v = node.getInput<int>(port.name);
      return v ? std::optional<std::string>(std::to_string(v.value())) : std::nullopt;
    }
    case PortType::Double: {
      auto v = node.getInput<double>(port.name);
      return v ? std::optional<std::string>(formatNumber(v.value())) : std::nullopt;
    }
    case PortType::Bool: {
      auto v = node.getInput<bool>(port.name);
      return v ? std::optional<std::string>(v.value() ? "true" : "false") : std::nullopt;
    }
    default: {
      auto v = node.getInput<std::string>(port.name);
      return v ? std::optional<std::string>(v.value()) : std::nullopt;
    }
  }
}

// ---------------------------------------------------------------- KbStep

KbStep::KbStep(const std::string& name, const BT::NodeConfig& config, Kb& kb)
  : BT::DecoratorNode(name, config), kb_(kb)
{
  const std::string number = *literal(config, name, "step", true);
  try
  {
    std::size_t used = 0;
    number_ = std::stoi(number, &used);
    if(used != number.size() || number_ < 1)
    {
      throw std::invalid_argument(number);
    }
  }
  catch(const std::exception&)
  {
    throw BT::RuntimeError("KbStep `", name, "`: `step` counts from 1, not `", number, "`");
  }
  Step& st = kb_.declareStep(number_);
  if(name.rfind("step ", 0) == 0)
  {
    st.label = name;
  }
  auto formula = [&](const std::string& t) { return kb_.formula(t); };
  auto effect = [&](const std::string& t) { return kb_.effect(t); };
  st.start_effect = compiled(literal(config, name, "start_effect", false), name, effect);
  st.end_effect = compiled(literal(config, name, "end_effect", false), name, effect);
  st.start_condition =
      compiled(literal(config, name, "start_condition", false), name, formula);
  st.over_all_condition =
      compiled(literal(config, name, "over_all_condition", false), name, formula);
  st.end_condition = compiled(literal(config, name, "end_condition", false), name, formula);
}

BT::PortsList KbStep::providedPorts()
{
  return { BT::InputPort<int>("step", "the plan step, from 1"),
           BT::InputPort<std::string>("start_effect", "", "applied when the step starts"),
           BT::InputPort<std::string>("end_effect", "", "applied when the child succeeds"),
           BT::InputPort<std::string>("start_condition", "", "checked when the step starts"),
           BT::InputPort<std::string>("over_all_condition", "",
                                      "checked when an action of the step starts"),
           BT::InputPort<std::string>("end_condition", "", "checked when the child succeeds") };
}

NodeStatus KbStep::tick()
{
  Step& st = *kb_.step(number_);
  if(status() != NodeStatus::RUNNING)
  {
    setStatus(NodeStatus::RUNNING);
    kb_.stepEvent(StepEvent::Kind::Started, number_);
    // With at-start effects, the precondition is checked before they
    // apply; otherwise the step's action leaves check it.
    if(st.start_effect && st.start_condition && !kb_.holds(*st.start_condition))
    {
      kb_.noteFailure(name(), "its step's precondition does not hold: " +
                                  kb_.whyNot(*st.start_condition));
      return NodeStatus::FAILURE;
    }
    // Each run of the step applies its effects: a step redone (a retry
    // after a fault undid its work) re-establishes them.
    st.started = true;
    if(st.start_effect)
    {
      kb_.apply(*st.start_effect);
    }
  }
  kb_.enterStep(number_);
  NodeStatus s;
  try
  {
    s = child_node_->executeTick();
  }
  catch(...)
  {
    kb_.leaveStep();
    throw;
  }
  kb_.leaveStep();
  if(s != NodeStatus::SUCCESS && s != NodeStatus::FAILURE)
  {
    return s;
  }
  resetChild();
  if(s == NodeStatus::FAILURE)
  {
    return s;
  }
  if(st.end_condition && !kb_.holds(*st.end_condition))
  {
    kb_.noteFailure(name(), "its step's at-end condition does not hold: " +
                                kb_.whyNot(*st.end_condition));
    return NodeStatus::FAILURE;
  }
  st.finished = true;
  if(st.end_effect)
  {
    kb_.apply(*st.end_effect);
  }
  kb_.stepEvent(StepEvent::Kind::Finished, number_);
  return NodeStatus::SUCCESS;
}

// ------------------------------------------------------------ KB leaves

KbHolds::KbHolds(const std::string& name, const BT::NodeConfig& config, Kb& kb)
  : BT::ConditionNode(name, config), kb_(kb)
{
  formula_ = compiled(literal(config, name, "formula", true), name,
                      [&](const std::string& t) { return kb_.formula(t); });
}

BT::PortsList KbHolds::providedPorts()
{
  return { BT::InputPort<std::string>("formula", "a ground PDDL condition") };
}

namespace
{

/// What a condition returns while the sensors are dark, as btc's engine
/// has it (a FAILURE says why); none when they are not.
std::optional<NodeStatus> inBlackout(Kb& kb, const std::string& node)
{
  switch(kb.blackout())
  {
    case Kb::Blackout::Running:
      return NodeStatus::RUNNING;
    case Kb::Blackout::Failure:
      kb.noteFailure(node, "sensor blackout: the condition cannot be read");
      return NodeStatus::FAILURE;
    default:
      return std::nullopt;
  }
}

}  // namespace

NodeStatus KbHolds::tick()
{
  if(!formula_)
  {
    return NodeStatus::SUCCESS;
  }
  if(const auto dark = inBlackout(kb_, name()))
  {
    return *dark;
  }
  if(kb_.holds(*formula_))
  {
    return NodeStatus::SUCCESS;
  }
  kb_.noteFailure(name(), "the condition does not hold: " + kb_.whyNot(*formula_));
  return NodeStatus::FAILURE;
}

KbApply::KbApply(const std::string& name, const BT::NodeConfig& config, Kb& kb)
  : BT::SyncActionNode(name, config), kb_(kb)
{
  effect_ = compiled(literal(config, name, "effect", true), name,
                     [&](const std::string& t) { return kb_.effect(t); });
}

BT::PortsList KbApply::providedPorts()
{
  return { BT::InputPort<std::string>("effect", "a ground PDDL effect") };
}

NodeStatus KbApply::tick()
{
  if(effect_)
  {
    kb_.apply(*effect_);
  }
  return NodeStatus::SUCCESS;
}

WaitForStep::WaitForStep(const std::string& name, const BT::NodeConfig& config, Kb& kb)
  : BT::ActionNodeBase(name, config), kb_(kb)
{
  const std::string t = *literal(config, name, "step", true);
  try
  {
    std::size_t used = 0;
    step_ = std::stoi(t, &used);
    if(used != t.size() || step_ < 1)
    {
      throw std::invalid_argument(t);
    }
  }
  catch(const std::exception&)
  {
    throw BT::RuntimeError("port `step` of `WaitForStep`: `", t, "` is not a step number");
  }
}

BT::PortsList WaitForStep::providedPorts()
{
  return { BT::InputPort<int>("step", "the plan step to wait for, from 1") };
}

NodeStatus WaitForStep::tick()
{
  const Step* s = kb_.step(step_);
  if(s == nullptr)
  {
    kb_.noteFailure(name(), "there is no step " + std::to_string(step_));
    return NodeStatus::FAILURE;
  }
  return s->finished || !s->declared ? NodeStatus::SUCCESS : NodeStatus::RUNNING;
}

// ------------------------------------------------------------- Condition

Condition::Condition(const std::string& name, const BT::NodeConfig& config, Kb& kb,
                     std::string formula, std::vector<PortSpec> ports)
  : BT::ConditionNode(name, config), kb_(kb), formula_(std::move(formula)),
    ports_(std::move(ports))
{}

std::string Condition::groundFormula() const
{
  return substitute(formula_, [&](const std::string& var) -> std::optional<std::string> {
    for(const auto& p : ports_)
    {
      if(p.name == var)
      {
        return portText(*this, p);
      }
    }
    return std::nullopt;
  });
}

NodeStatus Condition::tick()
{
  if(blank(formula_))
  {
    return NodeStatus::SUCCESS;
  }
  if(const auto dark = inBlackout(kb_, name()))
  {
    return *dark;
  }
  const std::string text = groundFormula();
  FormulaId f = 0;
  try
  {
    f = kb_.formula(text);
  }
  catch(const KbError& e)
  {
    kb_.noteFailure(name(), e.what());
    return NodeStatus::FAILURE;
  }
  if(kb_.holds(f))
  {
    return NodeStatus::SUCCESS;
  }
  kb_.noteFailure(name(), "the condition does not hold: " + kb_.whyNot(f));
  return NodeStatus::FAILURE;
}

// ---------------------------------------------------------------- Action

Action::Action(const std::string& name, const BT::NodeConfig& config, Kb& kb)
  : BT::ActionNodeBase(name, config), kb_(kb)
{}

Step* Action::step() const
{
  return kb_.step(kb_.currentStep());
}

bool Action::preconditionHolds()
{
  if(const Step* st = step())
  {
    if(const auto pre = st->leafCheck(); pre && !kb_.holds(*pre))
    {
      kb_.noteFailure(name(),
                      "its step's precondition does not hold: " + kb_.whyNot(*pre));
      return false;
    }
  }
  return true;
}

NodeStatus Action::onStart()
{
  if(!preconditionHolds())
  {
    return NodeStatus::FAILURE;
  }
  if(kb_.ticks_per_action <= 0)
  {
    return NodeStatus::SUCCESS;
  }
  remaining_ = kb_.ticks_per_action;
  return NodeStatus::RUNNING;
}

NodeStatus Action::onRunning()
{
  return --remaining_ <= 0 ? NodeStatus::SUCCESS : NodeStatus::RUNNING;
}

NodeStatus Action::tick()
{
  return status() == NodeStatus::RUNNING ? onRunning() : onStart();
}

void Action::halt()
{
  if(status() == NodeStatus::RUNNING)
  {
    onHalted();
  }
}

// --------------------------------------------------------- registration

void registerKbNodes(BT::BehaviorTreeFactory& factory, Kb& kb,
                     const std::vector<ConditionSpec>& conditions)
{
  factory.registerNodeType<KbStep>("KbStep", std::ref(kb));
  factory.registerNodeType<KbHolds>("KbHolds", std::ref(kb));
  factory.registerNodeType<KbApply>("KbApply", std::ref(kb));
  factory.registerNodeType<WaitForStep>("WaitForStep", std::ref(kb));
  for(const auto& c : conditions)
  {
    factory.registerNodeType<Condition>(c.id, inputPorts(c.ports), std::ref(kb), c.formula,
                                        c.ports);
  }
}

void registerSimulatedAction(BT::BehaviorTreeFactory& factory, Kb& kb, const std::string& id,
                             const std::vector<PortSpec>& ports)
{
  factory.registerNodeType<Action>(id, inputPorts(ports), std::ref(kb));
}

}  // namespace btc
