// The command line of a generated executor (`btc executor`): loads a
// compiled tree and its world, registers the nodes, ticks the tree to the
// end and prints what happened.
#pragma once

#include <behaviortree_cpp/bt_factory.h>

#include "btc/kb.hpp"

namespace btc
{

/// Registers a rules file's nodes (the generated `registerNodes`).
using RegisterNodes = void (*)(BT::BehaviorTreeFactory&, Kb&);

/// `EXECUTOR TREE.xml WORLD.kb [--ticks-per-action N] [--max-ticks N]
/// [--btlog FILE.btlog]`: runs the tree with `Tree::tickExactlyOnce` until
/// it is no longer RUNNING (or N ticks ran; then it is halted) and prints
/// each plan step as it starts and finishes (`tick 3: started step 2:
/// (grasp ...)`), the final status (`status: SUCCESS after 9 ticks`), the
/// last failure, the goal check and the KB. Exit status: 0 when the tree
/// succeeded and the goal holds, 1 otherwise, 2 for bad input (with the
/// error on stderr). `--btlog` records the run with BT.CPP's FileLogger2
/// for Groot2.
///
/// `EXECUTOR --palette` prints the registered nodes as BT.CPP's
/// `<TreeNodesModel>` (`BT::writeTreeNodesModelXML`), which a rules file
/// can `import`.
int runExecutor(int argc, char** argv, RegisterNodes registerNodes);

}  // namespace btc
