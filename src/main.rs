//! The `voltex` command line: render, bake, export, compare, plan, import, preview, regress, farm, info,
//! bench, bench-hyper, bench-report, pareto. Each subcommand lives in `src/cli/<name>.rs`; this file parses and
//! dispatches.

mod cli;

use std::process::ExitCode;

use clap::Parser;

use cli::{Cli, Command};

fn main() -> ExitCode {
    cli::default_sigpipe();
    cli::private_runtime_dir();
    let result = match Cli::parse().command {
        Command::Render(args) => cli::render::run(args),
        Command::Bake(args) => cli::bake::run(args),
        Command::Export(args) => cli::export::run(args),
        Command::Compare(args) => cli::compare::run(args),
        Command::Plan(args) => cli::plan::run(args),
        Command::Import(args) => cli::import::run(args),
        Command::Preview(args) => {
            cli::keep_freed_memory();
            cli::preview::run(args)
        }
        // regress and farm exit with a status by cause (voltex::regress::exit).
        Command::Regress(args) => {
            return match voltex::regress::command(&args) {
                Ok(code) => ExitCode::from(code),
                Err(e) => {
                    eprint!("{}", e.report());
                    ExitCode::from(voltex::regress::exit::of_error(&e))
                }
            }
        }
        Command::Farm(args) => {
            return match cli::farm::run(args) {
                Ok(code) => ExitCode::from(code),
                Err(e) => {
                    match &e {
                        cli::farm::FarmError::Input(e) => eprint!("{}", e.report()),
                        e => eprintln!("error: {e}"),
                    }
                    ExitCode::from(e.code())
                }
            }
        }
        Command::Info => cli::info::run(),
        Command::Bench(args) => cli::bench::run(args),
        Command::BenchHyper(args) => cli::bench::run_hyper(args),
        Command::BenchReport(args) => cli::bench_report::run(args),
        Command::Pareto(args) => cli::pareto::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprint!("{}", e.report());
            ExitCode::FAILURE
        }
    }
}
