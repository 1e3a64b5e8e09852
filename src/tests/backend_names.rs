//! The names of the backends, in every list that holds them.

/// Every name `--backend` takes is built by `backend_by_name`, offered by the error for an
/// unknown one and described by `rest-embree backends`; the backends the tests and the bench
/// run on are among them. A backend added to one list and not the others fails here.
#[test]
fn every_backend_name_is_listed_everywhere() {
    use crate::accel::{all_backend_names, backend_by_name, backend_names, backend_report};
    let all = all_backend_names();
    let report = backend_report().unwrap().join("\n");
    let unknown = backend_by_name("no-such-backend")
        .err()
        .unwrap()
        .to_string();
    // Whole names, so that `bvh` is not found inside `bvh-f32`.
    let names = |text: &str| -> Vec<String> {
        text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
            .map(str::to_string)
            .collect()
    };
    let (described, offered) = (names(&report), names(&unknown));
    for name in &all {
        assert!(backend_by_name(name).is_ok(), "{name} is built");
        let name = name.to_string();
        assert!(
            described.contains(&name),
            "`backends` describes {name}:\n{report}"
        );
        assert!(
            offered.contains(&name),
            "the error for an unknown backend offers {name}"
        );
    }
    for name in backend_names() {
        assert!(
            all.contains(&name),
            "{name} is among the names --backend takes"
        );
    }
}

/// A build without Embree says so when asked for it, and how to get it (the command line
/// prefixes the flag). The message is built in every build, and the build without Embree
/// returns it for each of Embree's names (`backend_by_name`); `make test` checks that build
/// compiles and lints clean, and runs the tests once, in the build with Embree.
#[test]
fn a_build_without_embree_says_how_to_get_it() {
    let why = crate::accel::embree_not_in_this_build().to_string();
    assert!(
        why.contains("'embree' is not in this build") && why.contains("--features embree"),
        "{why}"
    );
    if cfg!(not(feature = "embree")) {
        assert_eq!(crate::accel::backend_names(), vec!["bvh"]);
        for name in ["embree", "embree-16", "embree-single"] {
            let asked = crate::accel::backend_by_name(name)
                .err()
                .unwrap()
                .to_string();
            assert_eq!(asked, why, "{name}");
        }
    }
}
