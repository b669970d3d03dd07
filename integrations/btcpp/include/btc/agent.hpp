// btc's closed loop in a BehaviorTree.CPP program: plan, compile, build
// each attempt's tree in the user's `BT::BehaviorTreeFactory` (their own
// nodes, btc's KB nodes, and simulated leaves for what they do not
// provide), tick it, and when it fails, hand the fault record and the
// reported faults back to btc, which replans from the state the failure
// left (the loop of `btc run --replan`, in btc-api).
//
//   BT::BehaviorTreeFactory factory;
//   btc::Agent agent(btc::Project::open("rules.btrules"), factory);
//   factory.registerNodeType<MoveToClient>("MoveTo", std::ref(agent.kb()));
//   btc::AgentReport report = agent.run();
//
// A node reports a fault with `kb.reportFault({...})` and returns FAILURE
// (see `btc::ReportedFault`); what comes from outside the tree is reported
// before a tick (`Agent::before_tick`). A reported `high_priority_order`
// whose goal does not hold halts the tree at once: the order comes first,
// and btc plans it.
#pragma once

#include <behaviortree_cpp/bt_factory.h>
#include <behaviortree_cpp/contrib/json.hpp>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "btc/api.hpp"
#include "btc/kb.hpp"

namespace btc
{

/// Why a tree failed: the failing leaf (its registration id and name), in
/// which plan step (1-based; 0 outside every step), and why.
struct FaultRecord
{
  std::string node_id;
  std::string node_name;
  int step = 0;
  std::string reason;
  long tick = 0;  ///< of the attempt
  /// The reported faults the failure is due to (their labels).
  std::vector<std::string> faults;
};

/// A step starting or finishing at a tick of one attempt.
struct StepTick
{
  long tick = 0;
  bool started = false;
  int step = 0;  ///< 1-based
};

/// One attempt as btc hands it to the executor.
struct AttemptInput
{
  int attempt = 0;  ///< 1-based
  std::string tree_xml;  ///< BT.CPP XML, for `createTreeFromText`
  std::vector<NodeInfo> nodes;
  std::vector<std::string> state;  ///< the facts the attempt starts from
  std::string goal;
  long tick = 0;  ///< ticks run before this attempt
  long max_ticks = 0;  ///< the most ticks the attempt may run
};

/// What an attempt came to, as the executor reports it to btc.
struct AttemptResult
{
  BT::NodeStatus status = BT::NodeStatus::IDLE;
  std::vector<std::string> state;  ///< the KB after the run
  long ticks = 0;
  int steps_done = 0;
  std::vector<FaultRecord> records;
  std::vector<ReportedFault> faults;
  std::vector<StepTick> steps;
};

struct AgentOptions
{
  /// Plans made after a failure, at most (the first plan does not count).
  int max_replans = 5;
  /// Ticks of all attempts together, at most.
  long max_ticks = 100000;
  /// Ticks a simulated action (one the factory has no node for) runs.
  int ticks_per_action = 1;
};

/// What the loop came to. `json` is btc's whole report (attempts with
/// their plans and fault records, replans, faults, the final goal).
struct AgentReport
{
  bool goal_reached = false;
  std::string goal;
  int attempts = 0;
  int replans = 0;
  nlohmann::json json;
};

class Agent
{
public:
  /// An agent for `problem` (a path; none: the project's problem). Its KB
  /// is the problem's world; register your nodes in `factory` with
  /// `std::ref(agent.kb())`. The factory must outlive the agent's runs.
  Agent(Project project, BT::BehaviorTreeFactory& factory,
        const std::optional<std::string>& problem = std::nullopt);
  ~Agent();
  Agent(const Agent&) = delete;
  Agent& operator=(const Agent&) = delete;

  Kb& kb() { return kb_; }

  /// Runs the loop to the goal or until it must stop (no plan reaches the
  /// goal, the replan or tick limit). Throws `btc::Error` for bad input.
  AgentReport run(const AgentOptions& options = {});

  /// One attempt: builds `attempt`'s tree in the factory (registering btc's
  /// KB nodes, formula conditions and simulated actions the factory lacks),
  /// sets the KB to its state and goal, ticks it to the end (calling
  /// `before_tick` before every tick) and collects the record, the reported
  /// faults and the step events; a reported order whose goal does not hold
  /// ends it RUNNING, the tree halted. `run` calls it
  /// for every attempt; call it yourself to execute a tree btc compiled.
  AttemptResult execute(const AttemptInput& attempt, long max_ticks);

  /// Called after each attempt, with what it came to (for logging).
  std::function<void(const AttemptInput&, const AttemptResult&)> on_attempt;

  /// Called before each tick with the tick about to run, counted over the
  /// whole loop (`AttemptInput::tick` plus the attempt's ticks, 1-based),
  /// and the KB: where news from outside the tree comes in. Perception
  /// updating facts, or a fault no node meets: an order arrives or a part
  /// is found missing (`kb.reportFault({...})`, a fault of that tick), the
  /// sensors go dark (`kb.setBlackout(...)`, and back at the end).
  std::function<void(long tick, Kb& kb)> before_tick;

private:
  void registerMissing(const std::vector<NodeInfo>& nodes);
  /// Whether a reported order's goal does not hold: the order preempts
  /// the tree, as in btc's engine.
  bool orderFirst(const std::vector<ReportedFault>& faults);

  BT::BehaviorTreeFactory& factory_;
  Kb kb_;
  ::btc_agent* agent_ = nullptr;
  /// Where step events go while an attempt runs.
  std::vector<StepTick>* steps_sink_ = nullptr;
  const long* tick_now_ = nullptr;
};

/// A status's name as btc writes it: "success", "failure", "running".
const char* statusWord(BT::NodeStatus status);

}  // namespace btc
