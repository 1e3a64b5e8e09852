//! `rest-embree view`: its flags, handed to the viewer (src/view/).

use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub(crate) struct ViewArgs {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// The port to listen on (default: a free one).
    #[arg(long, default_value_t = 0)]
    pub port: u16,
    /// The address to listen on: 127.0.0.1 (the default) serves this machine alone; another
    /// (e.g. 0.0.0.0 on a cluster node) serves others, still only with the token.
    #[arg(long, value_name = "ADDR", default_value = "127.0.0.1")]
    pub bind: std::net::IpAddr,
    /// A host name the browser may reach the server by besides IP addresses, localhost and this
    /// machine's name (repeatable); requests naming any other Host are refused.
    #[arg(long = "allow-host", value_name = "NAME")]
    pub allow_hosts: Vec<String>,
    /// Print the URL without opening a browser.
    #[arg(long)]
    pub no_browser: bool,
    /// Where "render this view" writes its scene file and EXR.
    #[arg(long, value_name = "DIR", default_value = ".")]
    pub out: PathBuf,
    /// Intersection backend (see `rest-embree backends`).
    #[arg(long)]
    pub backend: Option<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Override a scene value, as `render --set` does (repeatable); the view starts from, and
    /// saves, the scene with them.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

pub(super) fn run_view(args: &ViewArgs) -> crate::Result<()> {
    super::set_threads(args.threads)?;
    let backend = args
        .backend
        .clone()
        .unwrap_or_else(|| crate::accel::default_backend_name().to_string());
    crate::view::run(&crate::view::Config {
        scene: args.scene.clone(),
        text: None,
        overrides: args
            .set
            .iter()
            .map(|s| (format!("--set {s}"), s.clone()))
            .collect(),
        tell_url: None,
        bind: args.bind,
        port: args.port,
        backend,
        out: args.out.clone(),
        allow_hosts: args.allow_hosts.clone(),
        open_browser: !args.no_browser,
    })
}
