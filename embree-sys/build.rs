//! Generates the raw Embree 3 bindings with bindgen, compiles the wrappers of Embree's inline
//! helpers with cc, and links libembree3. EMBREE_DIR overrides where Embree is found
//! (`$EMBREE_DIR/include/embree3/rtcore.h`, `$EMBREE_DIR/lib/libembree3.so`).

use std::env;
use std::path::{Path, PathBuf};

const HELP: &str = "Install Embree 3 and libclang: on Debian/Ubuntu `sudo apt-get install libembree-dev libclang-dev` \
(the README's set-up commands do this), or point EMBREE_DIR at an Embree 3 installation \
(with include/embree3/rtcore.h and lib/libembree3.so). To build without Embree, use \
`--no-default-features` (the pure-Rust BVH backend stays available).";

fn fail(what: &str) -> ! {
    eprintln!("\nerror: embree-sys: {what}\n{HELP}\n");
    panic!("embree-sys: {what}. {HELP}");
}

fn main() {
    println!("cargo:rerun-if-env-changed=EMBREE_DIR");
    println!("cargo:rerun-if-changed=wrapper.h");
    let (include, libdir) = match env::var_os("EMBREE_DIR") {
        Some(dir) => {
            let dir = PathBuf::from(dir);
            (Some(dir.join("include")), Some(dir.join("lib")))
        }
        None => (None, None),
    };
    let header_dirs: Vec<PathBuf> = match &include {
        Some(i) => vec![i.clone()],
        None => vec![
            PathBuf::from("/usr/include"),
            PathBuf::from("/usr/local/include"),
        ],
    };
    let Some(inc) = header_dirs
        .iter()
        .find(|d| d.join("embree3/rtcore.h").is_file())
    else {
        fail(&format!(
            "the Embree 3 header embree3/rtcore.h was not found in {}",
            header_dirs
                .iter()
                .map(|d| d.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ));
    };
    let lib_dirs: Vec<PathBuf> = match &libdir {
        Some(l) => vec![l.clone()],
        None => [
            "/usr/lib/x86_64-linux-gnu",
            "/usr/lib/aarch64-linux-gnu",
            "/usr/lib",
            "/usr/local/lib",
            "/usr/lib64",
        ]
        .iter()
        .map(PathBuf::from)
        .collect(),
    };
    let Some(lib) = lib_dirs.iter().find(|d| d.join("libembree3.so").exists()) else {
        fail(&format!(
            "the Embree 3 library libembree3.so was not found in {}",
            lib_dirs
                .iter()
                .map(|d| d.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ));
    };

    let out = PathBuf::from(env::var("OUT_DIR").unwrap());
    let wrappers = out.join("embree_inline_wrappers");
    let inc_arg = format!("-I{}", inc.display());
    let builder = bindgen::Builder::default()
        .header("wrapper.h")
        .clang_arg(&inc_arg)
        .allowlist_function("rtc.*")
        .allowlist_type("RTC.*")
        .allowlist_var("RTC.*")
        .rustified_enum("RTCError")
        .prepend_enum_name(false)
        .derive_default(true)
        .layout_tests(false)
        .wrap_static_fns(true)
        .wrap_static_fns_path(&wrappers)
        .parse_callbacks(Box::new(bindgen::CargoCallbacks::new()));
    // bindgen panics when it cannot load libclang; turn that into the install hint.
    let bindings =
        match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| builder.generate())) {
            Ok(Ok(b)) => b,
            Ok(Err(e)) => fail(&format!("bindgen could not parse the Embree headers: {e}")),
            Err(_) => fail("bindgen could not run libclang (is libclang-dev installed?)"),
        };
    bindings
        .write_to_file(out.join("bindings.rs"))
        .expect("write bindings");

    // The wrappers bindgen wrote include wrapper.h by path; compile them against the same headers.
    let crate_dir = PathBuf::from(env::var("CARGO_MANIFEST_DIR").unwrap());
    cc::Build::new()
        .file(wrappers.with_extension("c"))
        .include(&crate_dir)
        .include(inc)
        .flag_if_supported("-Wno-unused-function")
        .compile("embree_inline_wrappers");

    println!("cargo:rustc-link-search=native={}", lib.display());
    println!("cargo:rustc-link-lib=dylib=embree3");
    if libdir.is_some() {
        println!("cargo:rustc-link-arg=-Wl,-rpath,{}", lib.display());
    }
    println!("cargo:include={}", inc.display());
    let _ = Path::new(".");
}
