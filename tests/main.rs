//! pilgrim end to end: the program run as a user runs it, its outputs read
//! back by the readers a shop has.
//!
//! One test binary for all of them: each binary links the kernel and its
//! dependencies statically (about 40 MB), so one per file cost a fresh test
//! build a link and that much disk each. The files stay one per area; run one
//! with a filter, e.g. `cargo test --test pilgrim_e2e caliber::`.

mod common;

mod architecture;

mod bodies;
mod caliber;
mod cli;
mod collisions;
mod compensate;
mod containment;
mod corpus;
mod docs;
mod drawings;
mod first_release;
mod hygiene;
mod kept;
mod machine_files;
mod mandrel;
mod mandrel_fidelity;
mod mutants;
mod plugins;
mod reader;
mod ring;
mod script_verify;
mod sdk;
mod thread;
mod times;
mod trust;
mod verify;
mod worm;

/// With `autotests = false` a test file that no `mod` line names is never
/// compiled: each file beside a binary's `main.rs` must be one of its modules.
#[test]
fn every_test_file_is_a_module_of_its_binary() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for dir in ["tests", "kernel/tests"] {
        let dir = root.join(dir);
        let main = std::fs::read_to_string(dir.join("main.rs")).unwrap();
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let Some(stem) = path.file_stem().and_then(|s| s.to_str()) else {
                continue;
            };
            if path.extension().is_some_and(|e| e == "rs") && stem != "main" {
                assert!(
                    main.lines().any(|l| l.trim() == format!("mod {stem};")),
                    "{} is not a module of {}: its tests would never run",
                    path.display(),
                    dir.join("main.rs").display()
                );
            }
        }
    }
}
