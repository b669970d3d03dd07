/*
 * btc's C API: load a rules project, check it, plan, compile a plan into a
 * behavior tree and emit it (BehaviorTree.CPP XML, JSON, ...), and run the
 * closed loop (plan, execute, fault, replan) with the host executing each
 * attempt's tree. Library: libbtc_capi (static or shared), built by
 * `cargo build -p btc-capi --release` (see docs/embedding.md).
 *
 * Conventions
 * - Texts are UTF-8 and NUL-terminated, in and out. A text btc returns
 *   (`char *`) is the caller's: free it with btc_string_free().
 * - Handles (btc_project, btc_plan, btc_tree, btc_agent) are opaque; each
 *   has its free function, which ignores NULL. A handle is used by one
 *   thread at a time; different handles may be used on different threads.
 * - Errors: a function that can fail takes `char **error` last. On success
 *   it sets `*error` to NULL; on failure it returns NULL (or nonzero) and
 *   sets `*error` to a JSON text the caller frees with btc_string_free():
 *     {"diagnostics": [{"code": "R003", "severity": "error",
 *       "message": "...", "path": "rules.btrules",
 *       "start": {"line": 3, "column": 5}, "end": {...},
 *       "hint": "..." or null, "labels": [...], "fixes": [...]}]}
 *   Codes are btc's stable diagnostic codes (docs/language.md). `error`
 *   may be NULL when the caller does not want the details.
 * - Nothing crashes the host: NULL or non-UTF-8 arguments and handles of
 *   another kind are refused with A001; a failure inside btc is caught and
 *   reported as A002 (a bug in btc: free the handles that call used).
 *   Freed or made-up pointers cannot be detected.
 */
#ifndef BTC_H
#define BTC_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct btc_project btc_project;
typedef struct btc_plan btc_plan;
typedef struct btc_tree btc_tree;
typedef struct btc_agent btc_agent;
typedef struct btc_reply btc_reply;

/* btc_tree_emit()'s targets: the outputs of `btc compile --emit`. */
#define BTC_TARGET_BTCPP_XML 0
#define BTC_TARGET_PY_TREES 1
#define BTC_TARGET_JSON 2
#define BTC_TARGET_DOT 3
#define BTC_TARGET_MERMAID 4
#define BTC_TARGET_COMMANDS 5

/* btc's version (a static text: do not free it). */
const char *btc_version(void);

/* Frees a text btc returned; NULL is ignored. */
void btc_string_free(char *text);

/* ---- Projects ---------------------------------------------------------- */

/* Loads the rules file at `path` and the files it names. */
btc_project *btc_project_open(const char *path, char **error);

/* A project from texts: the rules, the domain, the problem (may be NULL).
 * Nothing is read from disk; diagnostics name the texts `rules.btrules`,
 * `domain.pddl` and `problem.pddl` (or the names the rules give them). */
btc_project *btc_project_from_texts(const char *rules, const char *domain,
                                    const char *problem, char **error);

void btc_project_free(btc_project *project);

/* Every diagnostic of the rules file, its imports, domain and problem, as
 * a JSON array of diagnostics (see above), in `btc check`'s order. */
char *btc_project_check(const btc_project *project, char **error);

/* A plan made by btc's planner for `problem` (a path; NULL: the problem
 * given as a text, or the one the rules name). */
btc_plan *btc_project_plan(btc_project *project, const char *problem,
                           char **error);

/* Compiles `plan` with the project's rules for `problem` (as
 * btc_project_plan chooses it). The plan is checked against the problem
 * first, as `btc compile` does. */
btc_tree *btc_project_compile(btc_project *project, const btc_plan *plan,
                              const char *problem, char **error);

/* The `.kb` text of the problem's world (`btc compile --emit kb`): what
 * btc::Kb::fromText() reads. */
char *btc_project_knowledge_base(btc_project *project, const char *problem,
                                 char **error);

/* ---- Plans ------------------------------------------------------------- */

/* A plan for the PDDL domain and problem at these paths, without rules. */
btc_plan *btc_plan_files(const char *domain, const char *problem, char **error);

/* Reads a plan in any format `btc compile` reads (sas_plan, timed, ...). */
btc_plan *btc_plan_parse(const char *text, char **error);

/* The plan in sas_plan form (btc_plan_parse reads it back). */
char *btc_plan_to_text(const btc_plan *plan, char **error);

/* The plan as JSON: {"steps": [{"action": "move", "args": ["r1", "a"],
 * "time": null, "duration": null}], "cost": 4.0 or null}. */
char *btc_plan_to_json(const btc_plan *plan, char **error);

void btc_plan_free(btc_plan *plan);

/* ---- Trees ------------------------------------------------------------- */

/* The tree in one of the BTC_TARGET_ forms. BTC_TARGET_PY_TREES is refused
 * (E001) for a tree a py_trees module cannot run as btc's engine does. */
char *btc_tree_emit(const btc_tree *tree, int32_t target, char **error);

/* The leaf node ids the tree uses, as a JSON array of
 * {"id": "Grasp", "kind": "action" | "condition",
 *  "ports": [{"name": "robot", "direction": "input", "type": "robot"}],
 *  "formula": "(is_enabled ?robot)" or null}
 * (a port's type is a PDDL type or string, int, float, bool). */
char *btc_tree_nodes(const btc_tree *tree, char **error);

/* The plan's steps as a JSON array of texts, "(move floor_robot a b)". */
char *btc_tree_steps(const btc_tree *tree, char **error);

void btc_tree_free(btc_tree *tree);

/* ---- The closed loop ---------------------------------------------------- */

/* The executor of an agent: runs one attempt's tree and answers with
 * btc_reply_set(). `attempt_json` (valid during the call) is
 *   {"attempt": 1, "tree_xml": "<root ...>", "nodes": [as btc_tree_nodes],
 *    "steps": ["(move r1 a b)", ...],
 *    "state": ["(at r1 a)", "(= (battery r1) 20.0)"], "goal": "(and ...)",
 *    "tick": 0, "max_ticks": 100000}
 * (`state`: the facts the attempt starts from, which replace the problem's
 * initial state; `tick`: the loop's tick; `max_ticks`: the most ticks the
 * attempt may run). Return 0 with the outcome as the reply:
 *   {"status": "success" | "failure" | "running",
 *    "state": [facts and values after the run], "ticks": 12,
 *    "steps_done": 2,
 *    "records": [{"node_id": "MoveTo", "node_name": "move", "reason": "...",
 *                 "step": 3 or null, "tick": 9, "faults": ["faulty_gripper"]}],
 *    "faults": [{"kind": "faulty_gripper", "name": null, "robot": "r1",
 *                "part": null, "duration": null, "goal": null,
 *                "retract": ["(attach p r1)"], "add": ["(on p bin1)"],
 *                "tick": 9}]}
 * (records: why nodes failed, the last one the failure the loop replans
 * after; `tick`s count from the attempt's start; a fault's `kind` is one of
 * ARIAC's faulty_part, faulty_gripper, robot_malfunction, flipped_part,
 * sensor_blackout, high_priority_order, insufficient_parts,
 * human_too_close, and it changes the KB as the same fault of a scenario
 * file does, docs/runtime.md). Return nonzero when the attempt could not be
 * executed, with the reason as the reply text: the loop stops with that
 * error (X005), as it does for an answer it cannot read. The callback must
 * not unwind (no C++ exception may leave it). */
typedef int (*btc_execute_fn)(void *user, const char *attempt_json,
                              btc_reply *reply);

/* The executor's answer (copied). */
void btc_reply_set(btc_reply *reply, const char *text);

/* An agent over `project` for `problem` (a path; NULL: the project's). The
 * agent takes the project, also when it fails: do not free it after. */
btc_agent *btc_agent_new(btc_project *project, const char *problem,
                         char **error);

/* Runs the closed loop (the one `btc run --replan` runs): plans, hands each
 * attempt to `execute`, replans from what it reports, until the goal is
 * reached or the loop must stop. `options_json` may be NULL or
 *   {"max_replans": 5, "max_ticks": 100000}
 * Returns the report as JSON: {"attempts": [...], "replans": [...],
 * "faults": [...], "goal": "...", "goal_reached": true, "ticks": 7,
 * "stopped": [diagnostics], ...}. */
char *btc_agent_run(btc_agent *agent, const char *options_json,
                    btc_execute_fn execute, void *user, char **error);

void btc_agent_free(btc_agent *agent);

#ifdef __cplusplus
}
#endif

#endif /* BTC_H */
