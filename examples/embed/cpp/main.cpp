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
//               [(--fail ACTION:N | --fail-step N | --at-tick N) --kind KIND
//                [--robot R] [--part P] [--retract FACT]... [--add FACT]...
//                [--duration TICKS] [--goal GOAL] [--conditions running|failure]
//                [--reason TEXT]]
//
// One fault happens, and is reported to btc (`kb.reportFault`) where a real
// agent would learn of it:
//   --fail MoveTo:2    by the node of the second MoveTo goal;
//   --fail-step 3      by the first action node that starts in plan step 3
//                      or later;
//   --at-tick 2        from outside the tree, before tick 2 of the loop (an
//                      order arrives, a part is found missing, the sensors
//                      go dark): `Agent::before_tick`.
// What the fault then does to the robot is the server's: a faulty gripper
// aborts the goal (the part is dropped), a malfunction stops the robot's
// goals for `--duration` ticks, a person too close or a priority order
// pauses them, a sensor blackout makes the KB's conditions return RUNNING
// (or FAILURE) meanwhile. Prints each attempt's steps and the report;
// `--json` prints {"report": btc's report, "attempts": [{"steps": [...],
// "faults": [...]}], "kb": final facts}.
#include <btc/agent.hpp>
#include <btc/nodes.hpp>

#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace
{

/// The stand-in for an action server: a goal takes `work_ticks` polls; a
/// robot's goals stop while it is down and wait while it is paused (until
/// a tick of the loop's clock, `now`).
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
  /// The loop's tick, set before each one.
  long now = 0;
  std::map<std::string, long> down_until;
  std::map<std::string, long> paused_until;

  /// A goal for `robot`; -1 when the server rejects it (the robot is down).
  int sendGoal(const std::string& robot, bool abort)
  {
    if(isDown(robot))
    {
      return -1;
    }
    goals_.push_back(Goal{ robot, work_ticks, abort, State::Running });
    return static_cast<int>(goals_.size()) - 1;
  }

  State poll(int id)
  {
    Goal& g = goals_.at(static_cast<std::size_t>(id));
    if(g.state != State::Running)
    {
      return g.state;
    }
    if(isDown(g.robot))
    {
      g.state = State::Aborted;
    }
    else if(now >= until(paused_until, g.robot) && --g.left <= 0)
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

  bool isDown(const std::string& robot) const { return now < until(down_until, robot); }

  int canceled = 0;

private:
  struct Goal
  {
    std::string robot;
    int left;
    bool abort;
    State state;
  };

  static long until(const std::map<std::string, long>& m, const std::string& robot)
  {
    const auto it = m.find(robot);
    return it == m.end() ? 0 : it->second;
  }

  std::vector<Goal> goals_;
};

/// The one fault of a run, when and where it happens, and what it does to
/// the robot once it has.
class Fault
{
public:
  enum class Trigger
  {
    None,
    Action,  ///< the `occurrence`-th start of `action`
    Step,  ///< the first action start in plan step `step` or later
    Tick,  ///< before tick `tick` of the loop
  };

  Trigger trigger = Trigger::None;
  std::string action;
  int occurrence = 1;
  int step = 0;
  long tick = 0;
  btc::ReportedFault report;
  btc::Kb::Blackout blackout = btc::Kb::Blackout::Running;

  /// An action node of `step` starts: whether the fault happens now (once).
  bool dueAtStart(const std::string& id, const btc::Step* in_step)
  {
    const int n = ++started_[id];
    const bool due =
        (trigger == Trigger::Action && id == action && n >= occurrence) ||
        (trigger == Trigger::Step && in_step != nullptr && in_step->number >= step);
    return fire(due);
  }

  /// Before a tick: whether the fault happens now (once).
  bool dueBeforeTick(long now) { return fire(trigger == Trigger::Tick && now >= tick); }

  /// What the fault does besides its report: the server's robot stops or
  /// waits, the sensors go dark.
  void happen(FakeActionServer& server, long now)
  {
    const long end = now + report.duration.value_or(0);
    const std::string robot = report.robot.value_or("");
    if(report.kind == "robot_malfunction")
    {
      server.down_until[robot] = end;
    }
    else if(report.kind == "human_too_close" || report.kind == "high_priority_order")
    {
      server.paused_until[robot] = end;
    }
    else if(report.kind == "sensor_blackout")
    {
      dark_until_ = end;
    }
  }

  /// The sensors as they are at tick `now`.
  void sense(btc::Kb& kb, long now) const
  {
    kb.setBlackout(now < dark_until_ ? blackout : btc::Kb::Blackout::None);
  }

private:
  bool fire(bool due)
  {
    if(fired_ || !due)
    {
      return false;
    }
    fired_ = true;
    return true;
  }

  bool fired_ = false;
  long dark_until_ = 0;
  std::map<std::string, int> started_;
};

/// A robot action as a ROS 2 action client would run it: goal on start,
/// poll while RUNNING, cancel when halted, a fault report when it meets
/// one (a faulty gripper's when the server aborts the goal).
class ActionClient : public btc::Action
{
public:
  ActionClient(const std::string& name, const BT::NodeConfig& config, btc::Kb& kb,
               FakeActionServer& server, Fault& fault)
    : btc::Action(name, config, kb), server_(server), fault_(fault)
  {}

private:
  BT::NodeStatus onStart() override
  {
    dropping_ = false;
    if(fault_.dueAtStart(registrationName(), step()))
    {
      if(fault_.report.kind == "faulty_gripper")
      {
        dropping_ = true;
      }
      else
      {
        kb().reportFault(fault_.report);
        fault_.happen(server_, server_.now);
      }
    }
    if(!preconditionHolds())
    {
      if(dropping_)
      {
        // The gripper failed as the action began: still the fault's.
        kb().reportFault(fault_.report);
      }
      return BT::NodeStatus::FAILURE;
    }
    const auto robot = input<std::string>("robot");
    goal_ = server_.sendGoal(robot, dropping_);
    if(goal_ < 0)
    {
      kb().noteFailure(name(), "the server rejected the goal: `" + robot + "` is down");
      return BT::NodeStatus::FAILURE;
    }
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
        kb().noteFailure(name(), dropping_ ? "the gripper dropped the part"
                                           : "the server aborted the goal");
        if(dropping_)
        {
          kb().reportFault(fault_.report);
        }
        return BT::NodeStatus::FAILURE;
    }
  }

  void onHalted() override { server_.cancel(goal_); }

  FakeActionServer& server_;
  Fault& fault_;
  int goal_ = -1;
  bool dropping_ = false;
};

btc::PortSpec port(const char* name)
{
  return btc::PortSpec{ name, btc::PortType::String, "" };
}

int usage()
{
  std::cerr << "usage: ariac_agent RULES [--problem PROBLEM] [--work-ticks N] [--json]\n"
               "         [(--fail ACTION:N | --fail-step N | --at-tick N) --kind KIND\n"
               "          [--robot R] [--part P] [--retract FACT]... [--add FACT]...\n"
               "          [--duration TICKS] [--goal GOAL] [--conditions running|failure]\n"
               "          [--reason TEXT]]\n";
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
  Fault fault;
  btc::ReportedFault& report = fault.report;
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
      fault.trigger = Fault::Trigger::Action;
      fault.action = v.substr(0, colon);
      fault.occurrence = colon == std::string::npos ? 1 : std::stoi(v.substr(colon + 1));
    }
    else if(a == "--fail-step")
    {
      fault.trigger = Fault::Trigger::Step;
      fault.step = std::stoi(args[++i]);
    }
    else if(a == "--at-tick")
    {
      fault.trigger = Fault::Trigger::Tick;
      fault.tick = std::stol(args[++i]);
    }
    else if(a == "--kind")
    {
      report.kind = args[++i];
    }
    else if(a == "--robot")
    {
      report.robot = args[++i];
    }
    else if(a == "--part")
    {
      report.part = args[++i];
    }
    else if(a == "--retract")
    {
      report.retract.push_back(args[++i]);
    }
    else if(a == "--add")
    {
      report.add.push_back(args[++i]);
    }
    else if(a == "--duration")
    {
      report.duration = std::stol(args[++i]);
    }
    else if(a == "--goal")
    {
      report.goal = args[++i];
    }
    else if(a == "--conditions" && (args[i + 1] == "running" || args[i + 1] == "failure"))
    {
      fault.blackout =
          args[++i] == "running" ? btc::Kb::Blackout::Running : btc::Kb::Blackout::Failure;
    }
    else if(a == "--reason")
    {
      report.reason = args[++i];
    }
    else
    {
      return usage();
    }
  }
  if(fault.trigger != Fault::Trigger::None && report.kind.empty())
  {
    return usage();
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
                                             std::ref(server), std::ref(fault));
    }
    // News from outside the tree: the clock the server runs on, a fault
    // due at this tick, the sensors.
    agent.before_tick = [&](long tick, btc::Kb& kb) {
      server.now = tick;
      if(fault.dueBeforeTick(tick))
      {
        kb.reportFault(report);
        fault.happen(server, tick);
      }
      fault.sense(kb, tick);
    };

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

    const btc::AgentReport result = agent.run();
    if(as_json)
    {
      nlohmann::json out{ { "report", result.json },
                          { "attempts", attempts },
                          { "kb", agent.kb().snapshot() },
                          { "canceled_goals", server.canceled } };
      std::cout << out.dump(2) << "\n";
    }
    else
    {
      std::cout << "goal " << (result.goal_reached ? "reached" : "not reached") << ": "
                << result.goal << " (" << result.replans << " replans, " << server.canceled
                << " goals canceled)\n";
    }
    return result.goal_reached ? 0 : 1;
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
