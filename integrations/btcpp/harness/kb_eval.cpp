// Test harness: evaluates formulas and applies effects with btc's C++
// knowledge base, so its answers can be compared with btc's own KB
// (tests/btcpp_kb.rs).
//
//   btc_kb_eval WORLD.kb COMMANDS
// COMMANDS has one command a line: `holds FORMULA`, `apply EFFECT`,
// `snapshot`, `goal`. Output, one line per command (a snapshot: one line
// per fact, then `end`): `true` / `false` / `ok` / `error MESSAGE`.
#include <btc/kb.hpp>

#include <fstream>
#include <iostream>
#include <string>

int main(int argc, char** argv)
{
  if(argc != 3)
  {
    std::cerr << "usage: btc_kb_eval WORLD.kb COMMANDS\n";
    return 2;
  }
  try
  {
    btc::Kb kb = btc::Kb::fromFile(argv[1]);
    std::ifstream in(argv[2]);
    std::string line;
    while(std::getline(in, line))
    {
      try
      {
        if(line.rfind("holds ", 0) == 0)
        {
          std::cout << (kb.holds(line.substr(6)) ? "true" : "false") << "\n";
        }
        else if(line.rfind("apply ", 0) == 0)
        {
          kb.apply(line.substr(6));
          std::cout << "ok\n";
        }
        else if(line == "snapshot")
        {
          for(const auto& f : kb.snapshot())
          {
            std::cout << f << "\n";
          }
          std::cout << "end\n";
        }
        else if(line == "goal")
        {
          std::cout << (kb.goalHolds() ? "true" : "false") << "\n";
        }
      }
      catch(const btc::KbError& e)
      {
        std::cout << "error " << e.what() << "\n";
      }
    }
  }
  catch(const std::exception& e)
  {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
