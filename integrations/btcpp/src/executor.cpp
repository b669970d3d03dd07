#include "btc/executor.hpp"

#include <behaviortree_cpp/loggers/bt_file_logger_v2.h>
#include <behaviortree_cpp/xml_parsing.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace btc
{

namespace
{

const char* const kUsage =
    "usage: EXECUTOR TREE.xml WORLD.kb [--ticks-per-action N] [--max-ticks N]\n"
    "                [--btlog FILE.btlog]\n"
    "       EXECUTOR --palette    print the nodes' <TreeNodesModel> "
    "(BT::writeTreeNodesModelXML)\n"
    "TREE.xml: `btc compile RULES --plan PLAN --emit btcpp`; WORLD.kb: the same with "
    "`--emit kb`.\n";

long number(const std::string& flag, const std::string& value)
{
  try
  {
    std::size_t used = 0;
    const long n = std::stol(value, &used);
    if(used == value.size() && n >= 0)
    {
      return n;
    }
  }
  catch(const std::exception&)
  {
  }
  throw std::runtime_error(flag + " takes a whole number of at least 0, not `" + value + "`");
}

const char* statusName(BT::NodeStatus s)
{
  switch(s)
  {
    case BT::NodeStatus::SUCCESS:
      return "SUCCESS";
    case BT::NodeStatus::FAILURE:
      return "FAILURE";
    case BT::NodeStatus::RUNNING:
      return "RUNNING";
    case BT::NodeStatus::SKIPPED:
      return "SKIPPED";
    default:
      return "IDLE";
  }
}

}  // namespace

int runExecutor(int argc, char** argv, RegisterNodes registerNodes)
{
  try
  {
    std::vector<std::string> files;
    long ticks_per_action = 1;
    long max_ticks = 100000;
    std::string btlog;
    bool palette = false;
    for(int i = 1; i < argc; ++i)
    {
      const std::string a = argv[i];
      const bool has_value = i + 1 < argc;
      if(a == "--ticks-per-action" && has_value)
      {
        ticks_per_action = number(a, argv[++i]);
      }
      else if(a == "--max-ticks" && has_value)
      {
        max_ticks = number(a, argv[++i]);
      }
      else if(a == "--btlog" && has_value)
      {
        btlog = argv[++i];
      }
      else if(a == "--palette")
      {
        palette = true;
      }
      else if(a == "-h" || a == "--help")
      {
        std::cout << kUsage;
        return 0;
      }
      else if(!a.empty() && a[0] == '-')
      {
        std::cerr << "error: unknown option `" << a << "`\n" << kUsage;
        return 2;
      }
      else
      {
        files.push_back(a);
      }
    }
    if(palette)
    {
      Kb kb = Kb::fromText("(kb 1)", "<no world>");
      BT::BehaviorTreeFactory factory;
      registerNodes(factory, kb);
      std::cout << BT::writeTreeNodesModelXML(factory) << "\n";
      return 0;
    }
    if(files.size() != 2)
    {
      std::cerr << kUsage;
      return 2;
    }
    Kb kb = Kb::fromFile(files[1]);
    kb.ticks_per_action = static_cast<int>(ticks_per_action);
    BT::BehaviorTreeFactory factory;
    registerNodes(factory, kb);
    long tick = 0;
    kb.onStepEvent([&](const StepEvent& e) {
      const Step* s = kb.step(e.step);
      std::cout << "tick " << tick << ": "
                << (e.kind == StepEvent::Kind::Started ? "started " : "finished ")
                << (s != nullptr ? s->label : "step " + std::to_string(e.step)) << "\n";
    });
    // BT.CPP resolves a bare file name against an empty parent folder.
    auto tree = factory.createTreeFromFile(std::filesystem::absolute(files[0]));
    std::unique_ptr<BT::FileLogger2> logger;
    if(!btlog.empty())
    {
      logger = std::make_unique<BT::FileLogger2>(tree, btlog);
    }
    BT::NodeStatus status = BT::NodeStatus::IDLE;
    while(tick < max_ticks)
    {
      ++tick;
      status = tree.tickExactlyOnce();
      if(status != BT::NodeStatus::RUNNING)
      {
        break;
      }
    }
    if(status == BT::NodeStatus::RUNNING)
    {
      tree.haltTree();
    }
    logger.reset();
    std::cout << "status: " << statusName(status) << " after " << tick << " ticks\n";
    if(status == BT::NodeStatus::FAILURE && !kb.lastFailure().empty())
    {
      std::cout << "failure: " << kb.lastFailure() << "\n";
    }
    const bool goal = kb.goalHolds();
    std::cout << "goal: " << (goal ? "reached" : "not reached: " + kb.goalFailure()) << "\n";
    std::cout << "kb:\n";
    for(const auto& fact : kb.snapshot())
    {
      std::cout << "  " << fact << "\n";
    }
    return status == BT::NodeStatus::SUCCESS && goal ? 0 : 1;
  }
  catch(const std::exception& e)
  {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace btc
