//! `btc`: the command line. Parses arguments, reads files, calls the
//! library and prints; nothing else lives here.

mod files;
mod pddl_cmd;
mod report;
mod validate_cmd;

use clap::{Parser, Subcommand, ValueEnum};
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

#[derive(Subcommand)]
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
    /// Check that a plan is valid: every step applicable, the goal reached.
    Validate {
        domain: PathBuf,
        problem: PathBuf,
        plan: PathBuf,
        #[arg(long, value_enum, default_value_t)]
        format: Format,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Pddl {
            files,
            domain,
            json,
            format,
        } => pddl_cmd::run(&files, domain.as_deref(), json, format),
        Command::Validate {
            domain,
            problem,
            plan,
            format,
        } => validate_cmd::run(&domain, &problem, &plan, format),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
