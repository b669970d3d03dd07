// The BT.CPP 4.10 peer of btc's engine tests and benchmarks: the same
// work done by real BehaviorTree.CPP, so that the two can be compared in
// one run (runtime/tests/script_fuzz.rs, runtime/benches/engine.rs). Built
// with the other harnesses by btc_testkit::btcpp_harness; not part of btc.
//
//   peer eval           one script per stdin line; prints its value or its
//                       error class, one line each
//   peer leaves N M     Repeat N x Sequence of M AlwaysSuccess, from XML:
//                       prints the milliseconds of the run
//   peer load FILE      load the XML tree in FILE and run it to the end:
//                       prints the milliseconds of load and run

#include <behaviortree_cpp/bt_factory.h>
#include <behaviortree_cpp/scripting/script_parser.hpp>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

using Clock = std::chrono::steady_clock;

static std::string error_class(const std::string& m) {
  if (m.find("Variable not found") != std::string::npos ||
      m.find("doesn't exist") != std::string::npos)
    return "not_found";
  if (m.find("not initialized") != std::string::npos ||
      m.find("undefined") != std::string::npos)
    return "not_initialized";
  return "type";
}

static std::string show(const BT::Any& v) {
  char buf[64];
  if (v.empty()) return "empty";
  if (v.isString()) return "str " + v.cast<std::string>();
  if (v.isType<int64_t>()) {
    std::snprintf(buf, sizeof buf, "int %lld", (long long)v.cast<int64_t>());
    return buf;
  }
  if (v.isType<bool>()) return std::string("bool ") + (v.cast<bool>() ? "1" : "0");
  if (v.isNumber()) {
    std::snprintf(buf, sizeof buf, "num %.17g", v.cast<double>());
    return buf;
  }
  return "other";
}

static int eval() {
  std::string line;
  while (std::getline(std::cin, line)) {
    auto bb = BT::Blackboard::create();
    BT::Ast::Environment env{bb, {}};
    std::string out;
    try {
      auto f = BT::ParseScript(line);
      if (!f) {
        out = "err syntax";
      } else {
        try {
          out = "ok " + show(f.value()(env));
        } catch (const std::exception& e) {
          out = "err " + error_class(e.what());
        }
      }
    } catch (const std::exception&) {
      out = "err syntax";
    }
    std::cout << out << "\n" << std::flush;
  }
  return 0;
}

static double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

static int leaves(int cycles, int n) {
  std::ostringstream x;
  x << "<root BTCPP_format=\"4\"><BehaviorTree ID=\"Main\"><Repeat num_cycles=\""
    << cycles << "\"><Sequence>";
  for (int i = 0; i < n; i++) x << "<AlwaysSuccess/>";
  x << "</Sequence></Repeat></BehaviorTree></root>";
  BT::BehaviorTreeFactory factory;
  auto tree = factory.createTreeFromText(x.str());
  auto t = Clock::now();
  auto s = tree.tickOnce();
  double ms = ms_since(t);
  if (s != BT::NodeStatus::SUCCESS) return 1;
  std::printf("%.3f\n", ms);
  return 0;
}

static int load(const char* path) {
  std::ifstream f(path);
  std::stringstream text;
  text << f.rdbuf();
  auto t = Clock::now();
  BT::BehaviorTreeFactory factory;
  auto tree = factory.createTreeFromText(text.str());
  auto s = tree.tickWhileRunning();
  double ms = ms_since(t);
  if (s != BT::NodeStatus::SUCCESS) return 1;
  std::printf("%.3f\n", ms);
  return 0;
}

int main(int argc, char** argv) {
  std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "eval") return eval();
  if (mode == "leaves" && argc == 4) return leaves(std::atoi(argv[2]), std::atoi(argv[3]));
  if (mode == "load" && argc == 3) return load(argv[2]);
  std::fprintf(stderr, "usage: peer eval | leaves CYCLES N | load FILE\n");
  return 2;
}
