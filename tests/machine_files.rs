//! Each built-in machine file against the plugin that describes the same
//! machine: the default jobs run through the kernel's generic solver
//! (`--machine kernel/machines/NAME.toml`) write the program the plugin's
//! closed form writes, to the program's last decimal. The caliber's passes
//! cross singular poses (the swivel at zero leaves the roll's turn free:
//! the bottom pass and the sizing section), which the generic solver must
//! settle as the plugin does.

use crate::common;

use common::{pilgrim, s, scratch};

/// `(script, built-in plugin, machine file, program file)`.
const PAIRS: [(&str, &str, &str, &str); 3] = [
    (
        "scripts/caliber.rhai",
        "Mannesmann",
        "kernel/machines/mannesmann.toml",
        "program.mpf",
    ),
    (
        "scripts/caliber.rhai",
        "LZ-250",
        "kernel/machines/lz-250.toml",
        "program.mpf",
    ),
    (
        "scripts/worm.rhai",
        "fanuc-0i-tc",
        "kernel/machines/fanuc-0i-tc.toml",
        "program.nc",
    ),
];

#[test]
fn each_machine_file_writes_its_plugins_program() {
    for (script, plugin, file, program) in PAIRS {
        let run = |machine: &str, name: &str| {
            let out = scratch("machine_files", name).join("out");
            let (code, _, err) = pilgrim(&["run", script, "--machine", machine, "--out", s(&out)]);
            assert_eq!(code, 0, "{script} on {machine}: {err}");
            std::fs::read_to_string(out.join(program)).unwrap()
        };
        let (ours, theirs) = (
            run(file, &format!("{plugin}-file")),
            run(plugin, &format!("{plugin}-plugin")),
        );
        let differ: Vec<(usize, (&str, &str))> = ours
            .lines()
            .zip(theirs.lines())
            .enumerate()
            .filter(|(_, (a, b))| a != b)
            .collect();
        assert!(
            differ.is_empty() && ours.lines().count() == theirs.lines().count(),
            "{file} against the plugin {plugin}: {} lines differ, the first {:?}",
            differ.len(),
            differ.first()
        );
    }
}
