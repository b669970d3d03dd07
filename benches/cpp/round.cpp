// One plan -> tree round on the ARIAC part task as a BehaviorTree.CPP agent
// meets it: plan from the problem, compile the plan, build the BT.CPP tree
// in the factory (with btc's KB nodes and the problem's world).
//
// In-process through btc's C API (btc::Project), and by the subprocess
// route a team uses without it (`btc plan`, `btc compile --emit btcpp`,
// `btc compile --emit kb`, read the files, build the tree), in one run.
//
//   btc_round EXAMPLE_DIR [--btc PATH] [--rounds N]
#include <btc/api.hpp>
#include <btc/nodes.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace
{

constexpr double kTargetMs = 1.0;

std::pair<double, double> percentiles(const std::function<void(int)>& round, int n)
{
  std::vector<double> ms;
  ms.reserve(static_cast<std::size_t>(n));
  for(int i = 0; i < n; ++i)
  {
    const auto t0 = std::chrono::steady_clock::now();
    round(i);
    const auto t1 = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  return { ms[ms.size() / 2], ms[static_cast<std::size_t>(0.99 * static_cast<double>(ms.size() - 1))] };
}

std::string slurp(const std::string& path)
{
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Registers what the tree uses that the factory lacks: formula conditions
/// and simulated actions (a real agent registers its own actions).
void registerNodes(BT::BehaviorTreeFactory& f, btc::Kb& kb, const std::vector<btc::NodeInfo>& nodes)
{
  for(const auto& n : nodes)
  {
    if(f.builders().count(n.id) != 0)
    {
      continue;
    }
    std::vector<btc::PortSpec> ports;
    for(const auto& p : n.ports)
    {
      ports.push_back(btc::PortSpec{ p.name, btc::PortType::String, "" });
    }
    if(n.kind == "condition")
    {
      f.registerNodeType<btc::Condition>(n.id, btc::inputPorts(ports), std::ref(kb),
                                         n.formula.value_or(""), ports);
    }
    else
    {
      btc::registerSimulatedAction(f, kb, n.id, ports);
    }
  }
}

}  // namespace

int main(int argc, char** argv)
{
  if(argc < 2)
  {
    std::cerr << "usage: btc_round EXAMPLE_DIR [--btc PATH] [--rounds N]\n";
    return 2;
  }
  const std::string dir = argv[1];
  std::string exe;
  int rounds = 2000;
  for(int i = 2; i + 1 < argc; i += 2)
  {
    const std::string a = argv[i];
    if(a == "--btc")
    {
      exe = argv[i + 1];
    }
    else if(a == "--rounds")
    {
      rounds = std::atoi(argv[i + 1]);
    }
  }
  try
  {
    btc::Project project = btc::Project::open(dir + "/rules.btrules");
    btc::Kb kb = btc::Kb::fromText(project.knowledgeBase());
    BT::BehaviorTreeFactory factory;
    btc::registerKbNodes(factory, kb);
    std::size_t nodes_built = 0;
    auto in_process = [&](int) {
      const btc::Plan plan = project.plan();
      const btc::Tree tree = project.compile(plan);
      registerNodes(factory, kb, tree.nodes());
      kb.resetSteps();
      auto bt = factory.createTreeFromText(tree.btcppXml());
      nodes_built += bt.subtrees.size();
    };
    for(int i = 0; i < 50; ++i)
    {
      in_process(i);
    }
    const auto [p50, p99] = percentiles(in_process, rounds);
    std::printf("in-process from C++:    p50 %.3f ms, p99 %.3f ms (target p50 < %.0f ms)\n", p50,
                p99, kTargetMs);
    if(exe.empty())
    {
      std::printf("subprocess route (C++): skipped, no --btc\n");
      return p50 < kTargetMs ? 0 : 1;
    }
    const std::string work = "btc_round_work";
    std::system(("mkdir -p " + work).c_str());
    auto by_subprocess = [&](int) {
      const std::string plan = work + "/plan.txt";
      const std::string run =
          exe + " plan " + dir + "/domain.pddl " + dir + "/problem.pddl -o " + plan +
          " --quiet && " + exe + " compile " + dir + "/rules.btrules --plan " + plan +
          " --problem " + dir + "/problem.pddl --emit btcpp -o " + work + "/tree.xml && " + exe +
          " compile " + dir + "/rules.btrules --plan " + plan + " --problem " + dir +
          "/problem.pddl --emit kb -o " + work + "/world.kb";
      if(std::system(("(" + run + ") >/dev/null 2>&1").c_str()) != 0)
      {
        throw std::runtime_error("the subprocess route failed: " + run);
      }
      btc::Kb world = btc::Kb::fromText(slurp(work + "/world.kb"));
      BT::BehaviorTreeFactory f;
      btc::registerKbNodes(f, world);
      // What `btc executor` generates for the example's rules.
      auto port = [](const char* name) { return btc::PortSpec{ name, btc::PortType::String, "" }; };
      btc::registerSimulatedAction(f, world, "MoveTo", { port("robot"), port("target") });
      btc::registerSimulatedAction(f, world, "Grasp",
                                   { port("robot"), port("part"), port("source") });
      btc::registerSimulatedAction(f, world, "Place",
                                   { port("robot"), port("part"), port("target") });
      btc::registerSimulatedAction(f, world, "Flip",
                                   { port("robot"), port("part"), port("container") });
      const std::vector<btc::PortSpec> robot{ port("robot") };
      f.registerNodeType<btc::Condition>("RobotNormal", btc::inputPorts(robot), std::ref(world),
                                         std::string("(is_enabled ?robot)"), robot);
      auto bt = f.createTreeFromText(slurp(work + "/tree.xml"));
      nodes_built += bt.subtrees.size();
    };
    const auto [s50, s99] = percentiles(by_subprocess, std::max(rounds / 20, 20));
    std::printf("subprocess route (C++): p50 %.3f ms, p99 %.3f ms (%.1fx the in-process round)\n",
                s50, s99, s50 / p50);
    return 0;
  }
  catch(const std::exception& e)
  {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}
