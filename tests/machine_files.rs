//! Each compiled-in machine's closed form against the kernel's generic
//! solver of the machine's own description: the plugin written out as a
//! machine file (`pilgrim machines --toml NAME`) and run through the chain
//! solver (`--machine FILE`) writes the program the plugin writes, to the
//! program's last decimal. The caliber's passes cross singular poses (the
//! swivel at zero leaves the roll's turn free: the bottom pass and the
//! sizing section), which the generic solver must settle as the plugin
//! does.

use crate::common;

use common::{pilgrim, s, scratch};

/// `(script, built-in plugin, program file)`.
const PAIRS: [(&str, &str, &str); 3] = [
    ("scripts/caliber.rhai", "Mannesmann", "program.mpf"),
    ("scripts/caliber.rhai", "LZ-250", "program.mpf"),
    ("scripts/worm.rhai", "fanuc-0i-tc", "program.nc"),
];

#[test]
fn each_plugin_writes_the_program_its_description_solves_to() {
    for (script, plugin, program) in PAIRS {
        let dir = scratch("machine_files", plugin);
        let (code, text, err) = pilgrim(&["machines", "--toml", plugin]);
        assert_eq!(code, 0, "{plugin}: {err}");
        let file = dir.join(format!("{plugin}.toml"));
        std::fs::write(&file, text).unwrap();
        let run = |machine: &str, name: &str| {
            let out = dir.join(name);
            let (code, _, err) = pilgrim(&["run", script, "--machine", machine, "--out", s(&out)]);
            assert_eq!(code, 0, "{script} on {machine}: {err}");
            std::fs::read_to_string(out.join(program)).unwrap()
        };
        let (ours, theirs) = (run(s(&file), "file"), run(plugin, "plugin"));
        let differ: Vec<(usize, (&str, &str))> = ours
            .lines()
            .zip(theirs.lines())
            .enumerate()
            .filter(|(_, (a, b))| a != b)
            .collect();
        assert!(
            differ.is_empty() && ours.lines().count() == theirs.lines().count(),
            "{plugin} solved from its description: {} lines differ, the first {:?}",
            differ.len(),
            differ.first()
        );
    }
}
