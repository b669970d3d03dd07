//! `btc`: the command line as a library. Parses arguments, reads files,
//! calls btc's crates and prints; nothing else lives here. The `btc`
//! binary (`main.rs`) and the Python package's `btc` command both run
//! [`run`].

pub mod alloc;
mod domain_lookup;
mod executor_cmd;
mod files;
mod init_cmd;
mod paths;
mod pddl_cmd;
mod plan_cmd;
mod report;
mod rules_cmd;
mod run_cmd;
mod stdout;
mod test_cmd;
mod trial_cmd;
mod validate_cmd;

use clap::{Parser, Subcommand, ValueEnum};

use std::ffi::OsString;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "btc",
    version,
    about = "Turns PDDL plans into executable behavior trees"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Default)]
pub enum Format {
    /// Human-readable reports (colored on a terminal).
    #[default]
    Text,
    /// One JSON document on stdout.
    Json,
}

// `defer`: a subcommand's arguments are built only when it is the one
// run, so `btc --version` and each command do not build all the others.
#[derive(Subcommand)]
#[command(defer = true)]
enum Command {
    /// Parse and check PDDL domains and problems.
    Pddl {
        /// Domain and problem files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// The domain to check problems against (default: the domain file
        /// beside each problem).
        #[arg(long)]
        domain: Option<PathBuf>,
        /// Print the parsed model as JSON.
        #[arg(long)]
        json: bool,
        /// How to print diagnostics.
        #[arg(long, value_enum, default_value_t)]
        format: Format,
    },
    /// Check a `.btrules` file against its PDDL domain.
    Check {
        rules: PathBuf,
        #[arg(long, value_enum, default_value_t)]
        format: Format,
    },
    /// Compile a plan with a rules file into a behavior tree.
    Compile {
        rules: PathBuf,
        /// The plan to compile.
        #[arg(long)]
        plan: PathBuf,
        /// The PDDL problem the plan solves (default: `STEM.pddl` beside the
        /// plan `STEM.EXT`, else the rules file's `problem`, else
        /// `problem.pddl` beside the plan or the rules file).
        #[arg(long)]
        problem: Option<PathBuf>,
        /// The PDDL domain (default: the rules file's `domain`).
        #[arg(long)]
        domain: Option<PathBuf>,
        /// The output format.
        #[arg(long, value_enum)]
        emit: EmitFormat,
        /// Write here (atomically) instead of to stdout.
        #[arg(short = 'o', long = "output")]
        output: Option<PathBuf>,
        /// Write nothing: exit 1 when the `-o` file (or the py_trees
        /// runtime beside it) would change.
        #[arg(long, requires = "output")]
        check: bool,
        /// BT.CPP: one flat tree instead of a SubTree per rule.
        #[arg(long)]
        inline: bool,
        /// py_trees: import leaf behaviours from this Python module.
        #[arg(long)]
        node_module: Option<String>,
        /// py_trees: paste btc's runtime into the module, or import it
        /// (`btc_runtime.py`, written beside an `-o` output).
        #[arg(long, value_enum, default_value_t = RuntimeArg::Inline)]
        runtime: RuntimeArg,
        /// py_trees: name the domain and problem files in the module's
        /// header (relative to the output's folder, as the JSON IR records
        /// them).
        #[arg(long)]
        source_paths: bool,
        /// Compile a plan that does not replay on its problem (a step whose
        /// precondition fails, a goal not reached), with warnings.
        #[arg(long)]
        allow_invalid_plan: bool,
        /// How to print diagnostics.
        #[arg(long, value_enum, default_value_t)]
        format: Format,
    },
    /// Write a C++ executor for BehaviorTree.CPP from a rules file: a
    /// CMake project with a node class per declared action and condition
    /// (nodes.hpp, yours: never overwritten, only appended to), the
    /// generated bases, a main that runs a compiled tree, and btc's support
    /// library.
    Executor {
        rules: PathBuf,
        /// The folder to write (created when missing).
        #[arg(short = 'o', long = "output")]
        output: PathBuf,
        /// The C++ namespace and executable name (`NAME_executor`); default:
        /// the rules file's folder name.
        #[arg(long)]
        name: Option<String>,
        /// Write nothing: report what is out of date (exit 1 if anything is).
        #[arg(long)]
        check: bool,
        /// How to print diagnostics.
        #[arg(long, value_enum, default_value_t)]
        format: Format,
    },
    /// Start a rules file from a PDDL domain: a rule per action, each
    /// calling a leaf declared with the action's parameters as typed ports.
    Init {
        domain: PathBuf,
        /// A problem for the rules file to name (its `problem` line).
        problem: Option<PathBuf>,
        /// The rules file to write (default: `rules.btrules` beside the
        /// domain); an existing file is never overwritten.
        #[arg(short = 'o', long = "output")]
        output: Option<PathBuf>,
    },
    /// Add a rule stub to a rules file for each domain action no rule
    /// covers (the file's own text is kept byte for byte).
    Stubs { rules: PathBuf },
    /// Snapshot tests of a rules file's trees and runs: each plan beside it
    /// (or in its `plans/` folder) is compiled and run, and compared with
    /// its snapshots in `snapshots/` (insta's `.snap` format); exit 1 on a
    /// change, with a diff and the new version as `.snap.new`.
    Test {
        rules: PathBuf,
        /// The tree formats to snapshot (repeat it; default: btcpp and
        /// mermaid). The run is always snapshotted.
        #[arg(long, value_enum)]
        emit: Vec<EmitFormat>,
        /// Take the new versions: write them over the stored snapshots.
        #[arg(long, conflicts_with = "check")]
        accept: bool,
        /// Write nothing (for CI): exit 1 on any new or changed snapshot.
        #[arg(long)]
        check: bool,
    },
    /// Format `.btrules` files in place.
    Fmt {
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Only report files that are not formatted (exit 1 if any).
        #[arg(long)]
        check: bool,
    },
    /// Run the language server on stdin/stdout (for editors).
    Lsp,
    /// Run a compiled plan (or a tree file) against the problem's simulated
    /// world; exit 0 only when the tree succeeds and the goal holds.
    Run(run_cmd::RunArgs),
    /// Run an ARIAC 2023 trial file on a cell: the task manager, a floor
    /// and a ceiling agent, the agility challenges, the competition's scores.
    Trial(trial_cmd::TrialArgs),
    /// Check that a plan is valid: every step applicable, the goal reached.
    Validate {
        domain: PathBuf,
        problem: PathBuf,
        plan: PathBuf,
        /// A timed plan's separation tolerance: events less than a tenth of
        /// it apart are simultaneous, and durations must match within it
        /// (as VAL's `-t`).
        #[arg(short = 't', long, value_name = "SECONDS", default_value_t = btc_pddl::validate::DEFAULT_EPSILON)]
        epsilon: f64,
        #[arg(long, value_enum, default_value_t)]
        format: Format,
    },
    /// Find a plan for a PDDL problem (`sas_plan` format).
    Plan {
        domain: PathBuf,
        problem: PathBuf,
        /// Write the plan here (atomically) instead of to stdout.
        #[arg(short = 'o', long = "output")]
        output: Option<PathBuf>,
        /// The search algorithm.
        #[arg(long, value_enum, default_value_t = SearchArg::Lama)]
        search: SearchArg,
        /// The heuristic (of `gbfs` and `astar`; `lama` uses h_FF and landmarks).
        #[arg(long, value_enum, default_value_t = HeuristicArg::Ff)]
        heuristic: HeuristicArg,
        /// `lama`: the work its restarts may spend improving the first
        /// plan (0: stop at the first plan).
        #[arg(long, value_name = "WORK", default_value_t = btc_planner::DEFAULT_IMPROVE)]
        improve: u64,
        /// Give up after this many seconds.
        #[arg(long, value_name = "S")]
        timeout: Option<f64>,
        /// Do not print search statistics on stderr.
        #[arg(short, long)]
        quiet: bool,
        #[arg(long, value_enum, default_value_t)]
        format: Format,
    },
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum SearchArg {
    /// LAMA: lazy greedy search with h_FF and landmarks, then restarts
    /// with weighted A* that improve the plan (the default).
    Lama,
    /// Eager greedy best-first search with one heuristic (fast, not optimal).
    Gbfs,
    /// A* (optimal with `lmcut`, `max` or `blind`).
    Astar,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum HeuristicArg {
    /// FF: the cost of a relaxed plan (with preferred operators).
    Ff,
    /// The additive heuristic.
    Add,
    /// The max heuristic (admissible).
    Max,
    /// No guidance (admissible).
    Blind,
    /// LM-cut (admissible; h_max where the task has conditional effects or
    /// derived predicates).
    Lmcut,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum EmitFormat {
    Btcpp,
    Pytrees,
    Json,
    Dot,
    Mermaid,
    Commands,
    /// The problem's world for btc's C++ knowledge base (`btc executor`).
    Kb,
}

impl From<EmitFormat> for rules_cmd::Output {
    fn from(f: EmitFormat) -> Self {
        use btc_emit::Format as F;
        use rules_cmd::Output::{Kb, Tree};
        match f {
            EmitFormat::Btcpp => Tree(F::Btcpp),
            EmitFormat::Pytrees => Tree(F::Pytrees),
            EmitFormat::Json => Tree(F::Json),
            EmitFormat::Dot => Tree(F::Dot),
            EmitFormat::Mermaid => Tree(F::Mermaid),
            EmitFormat::Commands => Tree(F::Commands),
            EmitFormat::Kb => Kb,
        }
    }
}

/// How a py_trees module gets btc's runtime.
#[derive(Clone, Copy, Debug, ValueEnum)]
enum RuntimeArg {
    /// Pasted into the module: one self-contained file.
    Inline,
    /// `from btc_runtime import ...`: smaller modules sharing one runtime.
    Import,
}

impl From<RuntimeArg> for btc_emit::pytrees::Runtime {
    fn from(r: RuntimeArg) -> Self {
        match r {
            RuntimeArg::Inline => btc_emit::pytrees::Runtime::Inline,
            RuntimeArg::Import => btc_emit::pytrees::Runtime::Import,
        }
    }
}

fn plan_options(
    search: SearchArg,
    heuristic: HeuristicArg,
    timeout: Option<f64>,
    improve: u64,
) -> anyhow::Result<btc_planner::Options> {
    use btc_planner::{Algorithm, Heuristic};
    let timeout = match timeout {
        Some(t) if !(t.is_finite() && t >= 0.0) => {
            anyhow::bail!("`--timeout` must be a number of seconds of at least 0, not {t}")
        }
        Some(t) => Some(std::time::Duration::from_secs_f64(t.min(1e9))),
        None => None,
    };
    Ok(btc_planner::Options {
        algorithm: match search {
            SearchArg::Lama => Algorithm::Lama,
            SearchArg::Gbfs => Algorithm::Gbfs,
            SearchArg::Astar => Algorithm::Astar,
        },
        heuristic: match heuristic {
            HeuristicArg::Ff => Heuristic::Ff,
            HeuristicArg::Add => Heuristic::Add,
            HeuristicArg::Max => Heuristic::Max,
            HeuristicArg::Blind => Heuristic::Blind,
            HeuristicArg::Lmcut => Heuristic::LmCut,
        },
        timeout,
        improve,
    })
}

/// `btc test`'s formats: trees only (default: BT.CPP XML and Mermaid).
fn test_formats(emit: Vec<EmitFormat>) -> anyhow::Result<Vec<btc_emit::Format>> {
    if emit.is_empty() {
        return Ok(vec![btc_emit::Format::Btcpp, btc_emit::Format::Mermaid]);
    }
    emit.into_iter()
        .map(|f| match rules_cmd::Output::from(f) {
            rules_cmd::Output::Tree(f) => Ok(f),
            rules_cmd::Output::Kb => {
                anyhow::bail!("`btc test` snapshots trees: `--emit kb` is not one")
            }
        })
        .collect()
}

/// Runs the command line `args` (the program's name first), as the `btc`
/// binary does: what it prints goes to this process's stdout and stderr,
/// and the exit status (0, 1 or 2, as docs/cli.md says) is returned.
pub fn run<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            // `--help` and `--version` are "errors" that exit 0.
            let _ = e.print();
            return ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2));
        }
    };
    let result = match cli.command {
        Command::Pddl {
            files,
            domain,
            json,
            format,
        } => pddl_cmd::run(&files, domain.as_deref(), json, format),
        Command::Check { rules, format } => rules_cmd::check(&rules, format),
        Command::Compile {
            rules,
            plan,
            problem,
            domain,
            emit,
            output,
            check,
            inline,
            node_module,
            runtime,
            source_paths,
            allow_invalid_plan,
            format,
        } => rules_cmd::compile(&rules_cmd::CompileArgs {
            rules,
            plan,
            problem,
            domain,
            emit: emit.into(),
            output,
            check,
            options: btc_emit::Options {
                inline,
                node_module,
                runtime: runtime.into(),
                source_paths,
            },
            allow_invalid_plan,
            format,
        }),
        Command::Executor {
            rules,
            output,
            name,
            check,
            format,
        } => executor_cmd::run(&executor_cmd::Args {
            rules: &rules,
            out: &output,
            name: name.as_deref(),
            check,
            format,
        }),
        Command::Init {
            domain,
            problem,
            output,
        } => init_cmd::init(&domain, problem.as_deref(), output.as_deref()),
        Command::Stubs { rules } => init_cmd::stubs(&rules),
        Command::Test {
            rules,
            emit,
            accept,
            check,
        } => test_formats(emit).and_then(|targets| {
            test_cmd::run(&test_cmd::TestArgs {
                rules,
                targets,
                accept,
                check,
            })
        }),
        Command::Fmt { files, check } => rules_cmd::fmt(&files, check),
        Command::Lsp => btc_lsp::run_stdio()
            .map(|()| ExitCode::SUCCESS)
            .map_err(anyhow::Error::from),
        Command::Run(args) => run_cmd::run(&args),
        Command::Trial(args) => trial_cmd::run(&args),
        Command::Validate {
            domain,
            problem,
            plan,
            epsilon,
            format,
        } => validate_cmd::run(&domain, &problem, &plan, epsilon, format),
        Command::Plan {
            domain,
            problem,
            output,
            search,
            heuristic,
            improve,
            timeout,
            quiet,
            format,
        } => plan_options(search, heuristic, timeout, improve).and_then(|options| {
            plan_cmd::run(&plan_cmd::PlanArgs {
                domain: &domain,
                problem: &problem,
                output: output.as_deref(),
                options,
                quiet,
                format,
            })
        }),
    };
    match result {
        Ok(code) => code,
        // The reader of the output stopped early (`| head`): it has what
        // it wanted, and there is nothing to report.
        Err(e) if e.is::<stdout::Closed>() => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

/// The number a process exits with for `code`, for hosts that take a
/// number (`sys.exit` in the Python package's `btc` command).
pub fn exit_status(code: ExitCode) -> u8 {
    // btc's commands exit 0, 1 or 2; ExitCode does not give its number.
    (0..=2).find(|&n| ExitCode::from(n) == code).unwrap_or(1)
}
