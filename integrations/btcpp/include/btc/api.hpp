// btc as a C++ library: projects, plans and trees over btc's C API
// (`btc.h`, library `btc_capi`), with errors as a C++ exception carrying
// btc's diagnostics. Header-only; link `btc::capi` (CMake).
//
//   btc::Project project = btc::Project::open("rules.btrules");
//   btc::Plan plan = project.plan();
//   btc::Tree tree = project.compile(plan);
//   std::string xml = tree.btcppXml();   // factory.createTreeFromText(xml)
//
// Every call that fails throws `btc::Error`; its `diagnostics()` say what
// and where (code, message, file, line, column, hint).
#pragma once

#include <btc.h>

#include <behaviortree_cpp/contrib/json.hpp>

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace btc
{

/// One of btc's diagnostics: a stable code (docs/language.md), where, what,
/// and what to do.
struct Diagnostic
{
  std::string code;
  std::string severity;  ///< "error" or "warning"
  std::string message;
  std::string path;
  int line = 0;  ///< 1-based; 0 for what is not in a file
  int column = 0;
  int end_line = 0;
  int end_column = 0;
  std::string hint;  ///< empty when there is none

  bool isError() const { return severity == "error"; }

  /// `path:line:column: severity[CODE]: message (hint: ...)`
  std::string toString() const
  {
    std::string s = path + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " +
                    severity + "[" + code + "]: " + message;
    if(!hint.empty())
    {
      s += " (hint: " + hint + ")";
    }
    return s;
  }

  static Diagnostic fromJson(const nlohmann::json& j)
  {
    Diagnostic d;
    d.code = j.value("code", "");
    d.severity = j.value("severity", "error");
    d.message = j.value("message", "");
    d.path = j.value("path", "");
    if(j.contains("start"))
    {
      d.line = j["start"].value("line", 0);
      d.column = j["start"].value("column", 0);
    }
    if(j.contains("end"))
    {
      d.end_line = j["end"].value("line", 0);
      d.end_column = j["end"].value("column", 0);
    }
    if(j.contains("hint") && j["hint"].is_string())
    {
      d.hint = j["hint"].get<std::string>();
    }
    return d;
  }
};

/// What btc refused, with the diagnostics that say why; `what()` is the
/// first of them.
class Error : public std::runtime_error
{
public:
  explicit Error(std::vector<Diagnostic> diagnostics)
    : std::runtime_error(diagnostics.empty() ? "btc refused the input" :
                                               diagnostics.front().toString())
    , diagnostics_(std::move(diagnostics))
  {}

  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }

  /// The error text of btc's C API (`{"diagnostics": [...]}`), freed here.
  static Error fromC(char* error_json)
  {
    std::vector<Diagnostic> ds;
    if(error_json != nullptr)
    {
      const auto j = nlohmann::json::parse(error_json, nullptr, false);
      btc_string_free(error_json);
      if(j.is_object() && j.contains("diagnostics") && j["diagnostics"].is_array())
      {
        for(const auto& d : j["diagnostics"])
        {
          ds.push_back(Diagnostic::fromJson(d));
        }
      }
    }
    return Error(std::move(ds));
  }

private:
  std::vector<Diagnostic> diagnostics_;
};

namespace capi
{

/// A text btc returned: copied into a std::string and freed; a null result
/// throws the call's error.
inline std::string text(char* result, char* error)
{
  if(result == nullptr)
  {
    throw Error::fromC(error);
  }
  std::string s(result);
  btc_string_free(result);
  return s;
}

/// A handle btc returned, or the call's error thrown.
template <class T>
T* handle(T* result, char* error)
{
  if(result == nullptr)
  {
    throw Error::fromC(error);
  }
  return result;
}

inline const char* orNull(const std::optional<std::string>& s)
{
  return s ? s->c_str() : nullptr;
}

}  // namespace capi

/// A plan step: `(action args...)`.
struct PlanStep
{
  std::string action;
  std::vector<std::string> args;
};

class Plan
{
public:
  /// Reads a plan in any format `btc compile` reads.
  static Plan parse(const std::string& text)
  {
    char* error = nullptr;
    return Plan(capi::handle(btc_plan_parse(text.c_str(), &error), error));
  }

  /// A plan for a PDDL domain and problem (paths), without rules.
  static Plan forFiles(const std::string& domain, const std::string& problem)
  {
    char* error = nullptr;
    return Plan(capi::handle(btc_plan_files(domain.c_str(), problem.c_str(), &error), error));
  }

  /// The sas_plan text (`Plan::parse` reads it back).
  std::string text() const
  {
    char* error = nullptr;
    return capi::text(btc_plan_to_text(p_.get(), &error), error);
  }

  std::vector<PlanStep> steps() const
  {
    char* error = nullptr;
    const auto j = nlohmann::json::parse(capi::text(btc_plan_to_json(p_.get(), &error), error));
    std::vector<PlanStep> out;
    for(const auto& s : j["steps"])
    {
      out.push_back(PlanStep{ s["action"].get<std::string>(),
                              s["args"].get<std::vector<std::string>>() });
    }
    return out;
  }

  const btc_plan* raw() const { return p_.get(); }

private:
  explicit Plan(btc_plan* p) : p_(p, btc_plan_free) {}
  friend class Project;
  std::shared_ptr<btc_plan> p_;
};

/// A leaf node id a tree uses (`Tree::nodes`).
struct NodeInfo
{
  struct Port
  {
    std::string name;
    std::string direction;  ///< "input" or "output"
    std::string type;  ///< a PDDL type, or string, int, float, bool
  };
  std::string id;
  std::string kind;  ///< "action" or "condition"
  std::vector<Port> ports;
  std::optional<std::string> formula;  ///< a condition defined by a formula

  static NodeInfo fromJson(const nlohmann::json& j)
  {
    NodeInfo n;
    n.id = j["id"].get<std::string>();
    n.kind = j["kind"].get<std::string>();
    for(const auto& p : j["ports"])
    {
      n.ports.push_back(Port{ p["name"].get<std::string>(), p["direction"].get<std::string>(),
                              p["type"].get<std::string>() });
    }
    if(j.contains("formula") && j["formula"].is_string())
    {
      n.formula = j["formula"].get<std::string>();
    }
    return n;
  }
};

/// A compiled tree: its BT.CPP XML (for `createTreeFromText`) and its other
/// forms.
class Tree
{
public:
  enum class Target
  {
    BtcppXml = BTC_TARGET_BTCPP_XML,
    PyTrees = BTC_TARGET_PY_TREES,
    Json = BTC_TARGET_JSON,
    Dot = BTC_TARGET_DOT,
    Mermaid = BTC_TARGET_MERMAID,
    Commands = BTC_TARGET_COMMANDS
  };

  std::string emit(Target target) const
  {
    char* error = nullptr;
    return capi::text(btc_tree_emit(t_.get(), static_cast<int32_t>(target), &error), error);
  }
  std::string btcppXml() const { return emit(Target::BtcppXml); }
  std::string json() const { return emit(Target::Json); }

  std::vector<NodeInfo> nodes() const
  {
    char* error = nullptr;
    const auto j = nlohmann::json::parse(capi::text(btc_tree_nodes(t_.get(), &error), error));
    std::vector<NodeInfo> out;
    for(const auto& n : j)
    {
      out.push_back(NodeInfo::fromJson(n));
    }
    return out;
  }

  std::vector<std::string> steps() const
  {
    char* error = nullptr;
    return nlohmann::json::parse(capi::text(btc_tree_steps(t_.get(), &error), error))
        .get<std::vector<std::string>>();
  }

private:
  explicit Tree(btc_tree* t) : t_(t, btc_tree_free) {}
  friend class Project;
  std::shared_ptr<btc_tree> t_;
};

/// A rules file and what it names, loaded once into btc's incremental
/// database: planning and compiling again re-do only what changed. It can
/// be moved, not copied.
class Project
{
public:
  static Project open(const std::string& rules_path)
  {
    char* error = nullptr;
    return Project(capi::handle(btc_project_open(rules_path.c_str(), &error), error));
  }

  /// From texts; nothing is read from disk.
  static Project fromTexts(const std::string& rules, const std::string& domain,
                           const std::optional<std::string>& problem = std::nullopt)
  {
    char* error = nullptr;
    return Project(capi::handle(btc_project_from_texts(rules.c_str(), domain.c_str(),
                                                       capi::orNull(problem), &error),
                                error));
  }

  /// Every diagnostic of the project, in `btc check`'s order.
  std::vector<Diagnostic> check() const
  {
    char* error = nullptr;
    const auto j = nlohmann::json::parse(capi::text(btc_project_check(p_.get(), &error), error));
    std::vector<Diagnostic> out;
    for(const auto& d : j)
    {
      out.push_back(Diagnostic::fromJson(d));
    }
    return out;
  }

  /// A plan for `problem` (a path; none: the project's problem).
  Plan plan(const std::optional<std::string>& problem = std::nullopt)
  {
    char* error = nullptr;
    return Plan(
        capi::handle(btc_project_plan(p_.get(), capi::orNull(problem), &error), error));
  }

  Tree compile(const Plan& plan, const std::optional<std::string>& problem = std::nullopt)
  {
    char* error = nullptr;
    return Tree(capi::handle(
        btc_project_compile(p_.get(), plan.raw(), capi::orNull(problem), &error), error));
  }

  /// The problem's world as `.kb` text, for `btc::Kb::fromText`.
  std::string knowledgeBase(const std::optional<std::string>& problem = std::nullopt)
  {
    char* error = nullptr;
    return capi::text(btc_project_knowledge_base(p_.get(), capi::orNull(problem), &error),
                      error);
  }

  btc_project* raw() { return p_.get(); }
  /// Gives up the handle (an agent takes it): the project is empty after.
  btc_project* release() { return p_.release(); }

private:
  explicit Project(btc_project* p) : p_(p, btc_project_free) {}
  std::unique_ptr<btc_project, void (*)(btc_project*)> p_;
};

}  // namespace btc
