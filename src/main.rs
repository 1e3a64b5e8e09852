use clap::Parser;

fn main() -> std::process::ExitCode {
    rest_embree::cli::run(rest_embree::cli::Cli::parse())
}
