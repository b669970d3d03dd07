#include "btc/agent.hpp"

#include <behaviortree_cpp/loggers/abstract_logger.h>

#include "btc/nodes.hpp"

#include <set>
#include <utility>

namespace btc
{

namespace
{

using nlohmann::json;

/// Keeps the last leaf that failed, with its step and why: the fault
/// record of a tree that then fails (as btc's engine records it).
class FailureObserver : public BT::StatusChangeLogger
{
public:
  FailureObserver(BT::TreeNode* root, Kb& kb, const long& tick)
    : BT::StatusChangeLogger(root), kb_(kb), tick_(tick)
  {}

  void callback(BT::Duration, const BT::TreeNode& node, BT::NodeStatus,
                BT::NodeStatus status) override
  {
    const auto type = node.type();
    if(status != BT::NodeStatus::FAILURE ||
       (type != BT::NodeType::ACTION && type != BT::NodeType::CONDITION))
    {
      return;
    }
    FaultRecord r;
    r.node_id = node.registrationName();
    r.node_name = node.name();
    r.step = kb_.currentStep();
    // A leaf outside every step (a monitor beside the plan) fails the step
    // that was running, as btc's engine records it.
    for(int s = 1; r.step == 0 && s <= kb_.stepCount(); ++s)
    {
      const Step* st = kb_.step(s);
      r.step = st != nullptr && st->started && !st->finished ? s : 0;
    }
    r.reason = kb_.lastFailureWhy();
    r.tick = tick_;
    last = std::move(r);
  }
  void flush() override {}

  std::optional<FaultRecord> last;

private:
  Kb& kb_;
  const long& tick_;
};

PortType portType(const std::string& t)
{
  if(t == "int")
  {
    return PortType::Int;
  }
  if(t == "float")
  {
    return PortType::Double;
  }
  if(t == "bool")
  {
    return PortType::Bool;
  }
  return PortType::String;
}

std::vector<PortSpec> portSpecs(const NodeInfo& n)
{
  std::vector<PortSpec> out;
  for(const auto& p : n.ports)
  {
    out.push_back(PortSpec{ p.name, portType(p.type), "" });
  }
  return out;
}

json faultJson(const ReportedFault& f)
{
  auto opt = [](const std::optional<std::string>& s) { return s ? json(*s) : json(nullptr); };
  return json{ { "kind", f.kind },
               { "name", f.name.empty() ? json(nullptr) : json(f.name) },
               { "part", opt(f.part) },
               { "robot", opt(f.robot) },
               { "duration", f.duration ? json(*f.duration) : json(nullptr) },
               { "goal", opt(f.goal) },
               { "retract", f.retract },
               { "add", f.add },
               { "tick", f.tick } };
}

json resultJson(const AttemptResult& r)
{
  json records = json::array();
  for(const auto& rec : r.records)
  {
    records.push_back(json{ { "node_id", rec.node_id },
                            { "node_name", rec.node_name },
                            { "reason", rec.reason },
                            { "step", rec.step > 0 ? json(rec.step) : json(nullptr) },
                            { "tick", rec.tick },
                            { "faults", rec.faults } });
  }
  json faults = json::array();
  for(const auto& f : r.faults)
  {
    faults.push_back(faultJson(f));
  }
  return json{ { "status", statusWord(r.status) },
               { "state", r.state },
               { "ticks", r.ticks },
               { "steps_done", r.steps_done },
               { "records", records },
               { "faults", faults } };
}

AttemptInput attemptFromJson(const json& j)
{
  AttemptInput a;
  a.attempt = j.value("attempt", 0);
  a.tree_xml = j.at("tree_xml").get<std::string>();
  for(const auto& n : j.at("nodes"))
  {
    a.nodes.push_back(NodeInfo::fromJson(n));
  }
  a.state = j.at("state").get<std::vector<std::string>>();
  a.goal = j.value("goal", "");
  a.tick = j.value("tick", 0L);
  a.max_ticks = j.value("max_ticks", 0L);
  return a;
}

struct Call
{
  Agent* agent;
};

/// The C callback btc calls for each attempt. No exception crosses the C
/// boundary: one thrown while executing becomes the executor's error.
extern "C" int executeTrampoline(void* user, const char* attempt_json, btc_reply* reply)
{
  auto* call = static_cast<Call*>(user);
  try
  {
    const auto attempt = attemptFromJson(json::parse(attempt_json));
    const AttemptResult r = call->agent->execute(attempt, attempt.max_ticks);
    btc_reply_set(reply, resultJson(r).dump().c_str());
    return 0;
  }
  catch(const std::exception& e)
  {
    btc_reply_set(reply, e.what());
    return 1;
  }
  catch(...)
  {
    btc_reply_set(reply, "the executor threw something that is not a std::exception");
    return 1;
  }
}

}  // namespace

const char* statusWord(BT::NodeStatus status)
{
  switch(status)
  {
    case BT::NodeStatus::SUCCESS:
      return "success";
    case BT::NodeStatus::FAILURE:
      return "failure";
    default:
      return "running";
  }
}

Agent::Agent(Project project, BT::BehaviorTreeFactory& factory,
             const std::optional<std::string>& problem)
  : factory_(factory), kb_(Kb::fromText(project.knowledgeBase(problem), "<project>"))
{
  char* error = nullptr;
  agent_ = capi::handle(btc_agent_new(project.release(), capi::orNull(problem), &error), error);
  registerKbNodes(factory_, kb_);
  kb_.onStepEvent([this](const StepEvent& e) {
    if(steps_sink_ != nullptr)
    {
      steps_sink_->push_back(StepTick{ *tick_now_, e.kind == StepEvent::Kind::Started, e.step });
    }
  });
}

Agent::~Agent()
{
  btc_agent_free(agent_);
}

void Agent::registerMissing(const std::vector<NodeInfo>& nodes)
{
  const auto& have = factory_.builders();
  for(const auto& n : nodes)
  {
    if(have.count(n.id) != 0)
    {
      continue;
    }
    if(n.kind == "condition")
    {
      factory_.registerNodeType<Condition>(n.id, inputPorts(portSpecs(n)), std::ref(kb_),
                                           n.formula.value_or(""), portSpecs(n));
    }
    else
    {
      registerSimulatedAction(factory_, kb_, n.id, portSpecs(n));
    }
  }
}

AttemptResult Agent::execute(const AttemptInput& attempt, long max_ticks)
{
  registerMissing(attempt.nodes);
  kb_.resetSteps();
  kb_.setState(attempt.state);
  if(!attempt.goal.empty())
  {
    kb_.setGoal(attempt.goal);
  }
  kb_.takeFaults();
  AttemptResult result;
  long tick = 0;
  steps_sink_ = &result.steps;
  tick_now_ = &tick;
  BT::NodeStatus status = BT::NodeStatus::IDLE;
  std::optional<FaultRecord> failed_leaf;
  try
  {
    auto tree = factory_.createTreeFromText(attempt.tree_xml);
    FailureObserver observer(tree.rootNode(), kb_, tick);
    // Faults reported before or during a tick happened at it.
    const auto collect = [&] {
      for(auto& f : kb_.takeFaults())
      {
        f.tick = tick;
        result.faults.push_back(std::move(f));
      }
    };
    while(tick < max_ticks)
    {
      ++tick;
      if(before_tick)
      {
        before_tick(attempt.tick + tick, kb_);
        collect();
        if(orderFirst(result.faults))
        {
          status = BT::NodeStatus::RUNNING;
          break;
        }
      }
      status = tree.tickExactlyOnce();
      collect();
      if(status != BT::NodeStatus::RUNNING || orderFirst(result.faults))
      {
        break;
      }
    }
    if(status == BT::NodeStatus::RUNNING)
    {
      // Halting a RUNNING user node lets it cancel its goal (onHalted).
      tree.haltTree();
    }
    failed_leaf = observer.last;
  }
  catch(...)
  {
    steps_sink_ = nullptr;
    tick_now_ = nullptr;
    throw;
  }
  steps_sink_ = nullptr;
  tick_now_ = nullptr;
  result.status = status;
  result.ticks = tick;
  result.state = kb_.snapshot();
  for(int s = 1; s <= kb_.stepCount(); ++s)
  {
    const Step* step = kb_.step(s);
    result.steps_done += step != nullptr && step->finished ? 1 : 0;
  }
  if(status == BT::NodeStatus::FAILURE && failed_leaf)
  {
    FaultRecord r = *failed_leaf;
    // A fault reported at the failing tick is what the failure is due to.
    for(const auto& f : result.faults)
    {
      if(f.tick == r.tick)
      {
        r.faults.push_back(f.name.empty() ? f.kind : f.name);
        if(!f.reason.empty())
        {
          r.reason = f.reason;
        }
      }
    }
    result.records.push_back(std::move(r));
  }
  if(on_attempt)
  {
    on_attempt(attempt, result);
  }
  return result;
}

bool Agent::orderFirst(const std::vector<ReportedFault>& faults)
{
  for(const auto& f : faults)
  {
    if(f.kind != "high_priority_order" || !f.goal)
    {
      continue;
    }
    try
    {
      if(!kb_.holds(*f.goal))
      {
        return true;
      }
    }
    catch(const KbError&)
    {
      // A goal that does not fit the problem: the loop refuses the report
      // when the attempt ends, with its diagnostic.
    }
  }
  return false;
}

AgentReport Agent::run(const AgentOptions& options)
{
  kb_.ticks_per_action = options.ticks_per_action;
  const json opts{ { "max_replans", options.max_replans }, { "max_ticks", options.max_ticks } };
  Call call{ this };
  char* error = nullptr;
  const std::string text = capi::text(
      btc_agent_run(agent_, opts.dump().c_str(), executeTrampoline, &call, &error), error);
  AgentReport report;
  report.json = json::parse(text);
  report.goal_reached = report.json.value("goal_reached", false);
  report.goal = report.json.value("goal", "");
  report.attempts = static_cast<int>(report.json.value("attempts", json::array()).size());
  report.replans = static_cast<int>(report.json.value("replans", json::array()).size());
  return report;
}

}  // namespace btc
