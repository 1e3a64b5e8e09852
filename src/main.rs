fn main() -> std::process::ExitCode {
    rest_embree::run_command_line()
}
