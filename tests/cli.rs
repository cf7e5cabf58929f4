//! The `pilgrim` program, run as a user runs it.

use std::process::Command;

fn pilgrim(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_pilgrim"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn version_and_machines() {
    let (code, out, _) = pilgrim(&["--version"]);
    assert_eq!(code, 0);
    assert!(
        out.starts_with(&format!("pilgrim {}", env!("CARGO_PKG_VERSION"))),
        "{out}"
    );
    let (code, out, _) = pilgrim(&["machines"]);
    assert_eq!(code, 0);
    for name in [
        "3K152VF20",
        "LZ-250",
        "Mannesmann",
        "fanuc-0i-tc",
        "vertical-mill",
    ] {
        assert!(out.contains(name), "{name} missing:\n{out}");
    }
    assert!(
        out.contains("U   linear   [0, 150] mm, up to 2000 mm/min [moves the rest]"),
        "{out}"
    );
    assert!(out.contains("A   rotary   [-370, 370] deg"), "{out}");
}

#[test]
fn machine_file_errors_name_file_and_line() {
    let dir = std::env::temp_dir().join(format!("pilgrim-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("lathe.toml");
    let text = pilgrim_kernel::machine::BUILTIN_SOURCES[3].1;
    std::fs::write(&good, text.replace("fanuc-0i-tc", "my-lathe")).unwrap();
    let (code, out, _) = pilgrim(&["machines", "--only-files", "--file", good.to_str().unwrap()]);
    assert_eq!(code, 0);
    assert!(
        out.contains("my-lathe") && !out.contains("3K152VF20"),
        "{out}"
    );
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, text.replace("max_feed = 12000.0", "max_feed = -1.0")).unwrap();
    let (code, _, err) = pilgrim(&["machines", "--file", bad.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(
        err.contains("bad.toml:") && err.contains("axis X: the maximum feed must be > 0"),
        "{err}"
    );
    let (code, _, err) = pilgrim(&["machines", "--file", "/no/such.toml"]);
    assert_eq!(code, 1);
    assert!(err.contains("/no/such.toml"), "{err}");
    let (code, _, _) = pilgrim(&["frobnicate"]);
    assert_eq!(code, 2);
    std::fs::remove_dir_all(&dir).ok();
}
