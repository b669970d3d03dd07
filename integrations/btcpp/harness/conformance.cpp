// Test harness: runs batches of trees in real BehaviorTree.CPP, tick by
// tick, and prints every status change of every node, so btc's engine can be
// compared with BT.CPP itself (runtime/tests/btcpp_conformance.rs).
//
// Input (a file or stdin): cases, each
//   case NAME TICKS TICK_MS
//   <root ...> ... </root>      (BT.CPP v4 XML, any number of lines)
//   end
// or, for a tree BT.CPP loads from a file (its <include>s read relative to
// it), `file PATH` in place of the XML.
// Leaves `Scripted` return the letters of their `script` port in turn
// (S: SUCCESS, F: FAILURE, R: RUNNING; cycling; empty or missing: FAILURE).
// The tree is ticked with Tree::tickExactlyOnce until it stops RUNNING or
// TICKS ticks ran, sleeping TICK_MS milliseconds between ticks.
//
// Output per case:
//   case NAME
//   tick T
//   N FROM TO      (node N in preorder, statuses I R S F K)
//   ...
//   status S|F|R
// or `error MESSAGE` when BT.CPP refuses the tree or throws while ticking.
// The root's reset to IDLE that Tree::tickRoot makes after the last tick is
// printed as `reset N FROM TO`, apart from the nodes' own changes.
//
// With --btlog DIR, each case also writes DIR/NAME.btlog with FileLogger2.
// `--builtins` prints the models of BT.CPP's own nodes
// (BT::writeTreeNodesModelXML of a bare factory) and exits.
#include <behaviortree_cpp/bt_factory.h>
#include <behaviortree_cpp/loggers/abstract_logger.h>
#include <behaviortree_cpp/loggers/bt_file_logger_v2.h>
#include <behaviortree_cpp/xml_parsing.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace
{

char letter(BT::NodeStatus s)
{
  switch(s)
  {
    case BT::NodeStatus::IDLE:
      return 'I';
    case BT::NodeStatus::RUNNING:
      return 'R';
    case BT::NodeStatus::SUCCESS:
      return 'S';
    case BT::NodeStatus::FAILURE:
      return 'F';
    default:
      return 'K';
  }
}

class Scripted : public BT::ActionNodeBase
{
public:
  Scripted(const std::string& name, const BT::NodeConfig& config)
    : BT::ActionNodeBase(name, config)
  {}

  static BT::PortsList providedPorts()
  {
    return { BT::InputPort<std::string>("script") };
  }

private:
  BT::NodeStatus tick() override
  {
    auto s = getInput<std::string>("script");
    if(!s || s.value().empty())
    {
      return BT::NodeStatus::FAILURE;
    }
    const char c = s.value()[pos_++ % s.value().size()];
    switch(c)
    {
      case 'S':
        return BT::NodeStatus::SUCCESS;
      case 'R':
        return BT::NodeStatus::RUNNING;
      default:
        return BT::NodeStatus::FAILURE;
    }
  }
  void halt() override {}

  std::size_t pos_ = 0;
};

struct Change
{
  const BT::TreeNode* node;
  BT::NodeStatus from;
  BT::NodeStatus to;
};

class Recorder : public BT::StatusChangeLogger
{
public:
  explicit Recorder(BT::TreeNode* root)
  {
    enableTransitionToIdle(true);
    subscribeToTreeChanges(root);
  }
  ~Recorder() override
  {
    unsubscribeFromTreeChanges();
  }
  void callback(BT::Duration, const BT::TreeNode& node, BT::NodeStatus from,
                BT::NodeStatus to) override
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    changes_.push_back({ &node, from, to });
  }
  void flush() override {}
  std::vector<Change> take()
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::vector<Change> out;
    out.swap(changes_);
    return out;
  }

private:
  std::mutex mutex_;
  std::vector<Change> changes_;
};

void runCase(const std::string& name, long ticks, long tick_ms, const std::string& xml,
             const std::string& btlog_dir)
{
  std::cout << "case " << name << "\n";
  try
  {
    BT::BehaviorTreeFactory factory;
    factory.registerNodeType<Scripted>("Scripted");
    const std::string file_prefix = "file ";
    auto tree = xml.rfind(file_prefix, 0) == 0 ?
                    factory.createTreeFromFile(xml.substr(file_prefix.size(),
                                                          xml.find_last_not_of(" \n") + 1 -
                                                              file_prefix.size())) :
                    factory.createTreeFromText(xml);
    std::map<const BT::TreeNode*, int> index;
    BT::applyRecursiveVisitor(static_cast<const BT::TreeNode*>(tree.rootNode()),
                              [&](const BT::TreeNode* n) {
                                const int i = static_cast<int>(index.size());
                                index.emplace(n, i);
                              });
    std::unique_ptr<BT::FileLogger2> btlog;
    const std::string btlog_path = btlog_dir + "/" + name + ".btlog";
    if(!btlog_dir.empty())
    {
      btlog = std::make_unique<BT::FileLogger2>(tree, btlog_path);
    }
    std::size_t changes_total = 0;
    Recorder rec(tree.rootNode());
    BT::NodeStatus status = BT::NodeStatus::RUNNING;
    for(long t = 1; t <= ticks && status == BT::NodeStatus::RUNNING; ++t)
    {
      if(t > 1 && tick_ms > 0)
      {
        std::this_thread::sleep_for(std::chrono::milliseconds(tick_ms));
      }
      status = tree.tickExactlyOnce();
      // Changes a timer thread made while the harness slept (a Timeout
      // halting its child) belong to this tick, before the tick's own.
      const std::vector<Change> changes = rec.take();
      changes_total += changes.size();
      std::cout << "tick " << t << "\n";
      for(std::size_t k = 0; k < changes.size(); ++k)
      {
        const Change& c = changes[k];
        const bool reset = k + 1 == changes.size() && c.node == tree.rootNode() &&
                           status != BT::NodeStatus::RUNNING && c.to == BT::NodeStatus::IDLE;
        std::cout << (reset ? "reset " : "") << index.at(c.node) << " " << letter(c.from) << " "
                  << letter(c.to) << "\n";
      }
    }
    std::cout << "status " << letter(status) << "\n";
    if(btlog)
    {
      // FileLogger2 writes from a thread that stops at once when the logger
      // is destroyed, dropping what it has not written yet: wait until every
      // change is in the file (header, XML, timestamp, 9 bytes a change).
      const std::size_t want = 18 + 1 + 4 + BT::WriteTreeToXML(tree, true, true).size() + 8 +
                               9 * changes_total;
      for(int i = 0; i < 500; ++i)
      {
        btlog->flush();
        std::error_code ec;
        if(std::filesystem::file_size(btlog_path, ec) >= want)
        {
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    }
  }
  catch(const std::exception& e)
  {
    std::string msg = e.what();
    for(auto& c : msg)
    {
      if(c == '\n')
      {
        c = ' ';
      }
    }
    std::cout << "error " << msg << "\n";
  }
}

}  // namespace

int main(int argc, char** argv)
{
  std::string btlog_dir;
  std::string input;
  for(int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    if(a == "--btlog" && i + 1 < argc)
    {
      btlog_dir = argv[++i];
    }
    else if(a == "--builtins")
    {
      const BT::BehaviorTreeFactory factory;
      std::cout << BT::writeTreeNodesModelXML(factory, true) << "\n";
      return 0;
    }
    else
    {
      input = a;
    }
  }
  std::ifstream file;
  if(!input.empty())
  {
    file.open(input);
    if(!file)
    {
      std::cerr << "error: cannot read " << input << "\n";
      return 2;
    }
  }
  std::istream& in = input.empty() ? std::cin : file;
  std::string line;
  while(std::getline(in, line))
  {
    if(line.rfind("case ", 0) != 0)
    {
      continue;
    }
    std::istringstream head(line.substr(5));
    std::string name;
    long ticks = 0;
    long tick_ms = 0;
    head >> name >> ticks >> tick_ms;
    std::string xml;
    while(std::getline(in, line) && line != "end")
    {
      xml += line;
      xml += '\n';
    }
    runCase(name, ticks, tick_ms, xml, btlog_dir);
  }
  return 0;
}
