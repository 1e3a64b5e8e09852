fn main() -> std::process::ExitCode {
    rest_embree::cli::main()
}
