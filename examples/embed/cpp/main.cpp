// An agent for the ARIAC 2023 floor robot (examples/ariac) in a
// BehaviorTree.CPP program: btc plans the part task, compiles the plan into
// a tree built in this program's factory, and when an action fails with a
// fault, replans from the state the fault left.
//
// The robot's actions (MoveTo, Grasp, Place, Flip) are one node class,
// `ActionClient`, standing in for a ROS 2 action client: it sends a goal
// when it starts, polls the server on every tick (RUNNING until the result
// comes), and cancels the goal when it is halted. The "server" here is a
// simulation in this file; with ROS 2 it would be rclcpp_action.
//
//   ariac_agent RULES [--problem PROBLEM] [--work-ticks N] [--json]
//               [--fail ACTION:N --kind KIND [--robot R] [--part P]
//                [--retract FACT]... [--add FACT]... [--reason TEXT]]
//
// `--fail MoveTo:2 --kind faulty_gripper ...` makes the server abort the
// second MoveTo goal; the node then reports that fault to btc
// (`kb.reportFault`), which applies its `--retract`/`--add` facts and
// replans. Prints each attempt's steps and the report; `--json` prints
// {"report": btc's report, "attempts": [{"steps": [...], "faults": [...]}],
// "kb": final facts}.
#include <btc/agent.hpp>
#include <btc/nodes.hpp>

#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace
{

/// The stand-in for an action server: a goal takes `work_ticks` polls, and
/// the `fail_at`-th goal of `fail_action` is aborted.
class FakeActionServer
{
public:
  enum class State
  {
    Running,
    Succeeded,
    Aborted,
    Canceled
  };

  int work_ticks = 2;
  std::string fail_action;
  int fail_at = 0;

  int sendGoal(const std::string& action)
  {
    const int n = ++sent_[action];
    goals_.push_back(Goal{ work_ticks, action == fail_action && n == fail_at, State::Running });
    return static_cast<int>(goals_.size()) - 1;
  }

  State poll(int id)
  {
    Goal& g = goals_.at(static_cast<std::size_t>(id));
    if(g.state == State::Running && --g.left <= 0)
    {
      g.state = g.abort ? State::Aborted : State::Succeeded;
    }
    return g.state;
  }

  void cancel(int id)
  {
    goals_.at(static_cast<std::size_t>(id)).state = State::Canceled;
    ++canceled;
  }

  int canceled = 0;

private:
  struct Goal
  {
    int left;
    bool abort;
    State state;
  };
  std::vector<Goal> goals_;
  std::map<std::string, int> sent_;
};

/// What the server's aborted result says, as a btc fault.
std::optional<btc::ReportedFault> injected;

/// A robot action as a ROS 2 action client would run it: goal on start,
/// poll while RUNNING, cancel when halted, a fault report when the server
/// aborts.
class ActionClient : public btc::Action
{
public:
  ActionClient(const std::string& name, const BT::NodeConfig& config, btc::Kb& kb,
               FakeActionServer& server)
    : btc::Action(name, config, kb), server_(server)
  {}

private:
  BT::NodeStatus onStart() override
  {
    goal_ = server_.sendGoal(registrationName());
    return BT::NodeStatus::RUNNING;
  }

  BT::NodeStatus onRunning() override
  {
    switch(server_.poll(goal_))
    {
      case FakeActionServer::State::Running:
        return BT::NodeStatus::RUNNING;
      case FakeActionServer::State::Succeeded:
        return BT::NodeStatus::SUCCESS;
      default:
        if(injected)
        {
          kb().reportFault(*injected);
        }
        return BT::NodeStatus::FAILURE;
    }
  }

  void onHalted() override { server_.cancel(goal_); }

  FakeActionServer& server_;
  int goal_ = -1;
};

btc::PortSpec port(const char* name)
{
  return btc::PortSpec{ name, btc::PortType::String, "" };
}

int usage()
{
  std::cerr << "usage: ariac_agent RULES [--problem PROBLEM] [--work-ticks N] [--json]\n"
               "         [--fail ACTION:N --kind KIND [--robot R] [--part P]\n"
               "          [--retract FACT]... [--add FACT]... [--reason TEXT]]\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv)
{
  std::vector<std::string> args(argv + 1, argv + argc);
  if(args.empty())
  {
    return usage();
  }
  std::optional<std::string> problem;
  FakeActionServer server;
  bool as_json = false;
  btc::ReportedFault fault;
  for(std::size_t i = 1; i < args.size(); ++i)
  {
    const std::string& a = args[i];
    const bool more = i + 1 < args.size();
    if(a == "--json")
    {
      as_json = true;
    }
    else if(!more)
    {
      return usage();
    }
    else if(a == "--problem")
    {
      problem = args[++i];
    }
    else if(a == "--work-ticks")
    {
      server.work_ticks = std::stoi(args[++i]);
    }
    else if(a == "--fail")
    {
      const std::string v = args[++i];
      const auto colon = v.find(':');
      server.fail_action = v.substr(0, colon);
      server.fail_at = colon == std::string::npos ? 1 : std::stoi(v.substr(colon + 1));
    }
    else if(a == "--kind")
    {
      fault.kind = args[++i];
    }
    else if(a == "--robot")
    {
      fault.robot = args[++i];
    }
    else if(a == "--part")
    {
      fault.part = args[++i];
    }
    else if(a == "--retract")
    {
      fault.retract.push_back(args[++i]);
    }
    else if(a == "--add")
    {
      fault.add.push_back(args[++i]);
    }
    else if(a == "--reason")
    {
      fault.reason = args[++i];
    }
    else
    {
      return usage();
    }
  }
  if(!server.fail_action.empty())
  {
    injected = fault;
  }

  try
  {
    BT::BehaviorTreeFactory factory;
    btc::Agent agent(btc::Project::open(args[0]), factory, problem);
    const std::map<std::string, std::vector<btc::PortSpec>> actions{
      { "MoveTo", { port("robot"), port("target") } },
      { "Grasp", { port("robot"), port("part"), port("source") } },
      { "Place", { port("robot"), port("part"), port("target") } },
      { "Flip", { port("robot"), port("part"), port("container") } },
    };
    for(const auto& [id, ports] : actions)
    {
      factory.registerNodeType<ActionClient>(id, btc::inputPorts(ports), std::ref(agent.kb()),
                                             std::ref(server));
    }

    nlohmann::json attempts = nlohmann::json::array();
    agent.on_attempt = [&](const btc::AttemptInput& in, const btc::AttemptResult& out) {
      nlohmann::json steps = nlohmann::json::array();
      for(const auto& s : out.steps)
      {
        steps.push_back({ { "tick", s.tick }, { "started", s.started }, { "step", s.step } });
      }
      nlohmann::json faults = nlohmann::json::array();
      for(const auto& f : out.faults)
      {
        faults.push_back(f.kind);
      }
      attempts.push_back({ { "attempt", in.attempt },
                           { "status", btc::statusWord(out.status) },
                           { "steps", steps },
                           { "faults", faults } });
      if(!as_json)
      {
        std::cout << "attempt " << in.attempt << ": " << btc::statusWord(out.status) << " after "
                  << out.ticks << " ticks, " << out.steps_done << " steps done\n";
        for(const auto& r : out.records)
        {
          std::cout << "  failed: " << r.node_id << " (" << r.node_name << ") in step " << r.step
                    << ": " << r.reason << "\n";
        }
      }
    };

    const btc::AgentReport report = agent.run();
    if(as_json)
    {
      nlohmann::json out{ { "report", report.json },
                          { "attempts", attempts },
                          { "kb", agent.kb().snapshot() },
                          { "canceled_goals", server.canceled } };
      std::cout << out.dump(2) << "\n";
    }
    else
    {
      std::cout << "goal " << (report.goal_reached ? "reached" : "not reached") << ": "
                << report.goal << " (" << report.replans << " replans, " << server.canceled
                << " goals canceled)\n";
    }
    return report.goal_reached ? 0 : 1;
  }
  catch(const btc::Error& e)
  {
    for(const auto& d : e.diagnostics())
    {
      std::cerr << d.toString() << "\n";
    }
    return 2;
  }
  catch(const std::exception& e)
  {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}
