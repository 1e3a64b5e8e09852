fn main() -> std::process::ExitCode {
    match rest_embree::cli::parse() {
        Ok(cli) => rest_embree::cli::run(cli),
        Err(code) => code,
    }
}
