//! The documentation as a newcomer meets it: a short README linking every
//! page of `docs/`, each page linking back, and every relative link
//! landing on a file that is there.

use crate::common::root;
use std::path::Path;

/// The relative link targets of a Markdown text (`](target)`), without
/// their anchors; web addresses left out.
fn links(text: &str) -> Vec<String> {
    text.split("](")
        .skip(1)
        .filter_map(|rest| rest.split_once(')').map(|(t, _)| t))
        .filter(|t| !t.contains("://") && !t.starts_with('#'))
        .map(|t| t.split('#').next().unwrap_or(t).to_owned())
        .collect()
}

/// Every command of the README's `sh` blocks that names real files runs
/// as written (`cargo run --release -- ARGS` is `pilgrim ARGS`, in the
/// repository's root), in order, exit 0: its outputs go to a scratch
/// directory instead of `out/`. Lines with placeholders (`FAMILY.rhai`,
/// `SHOP.MPF`, `[--plugin LIB]`, alternatives `a|b`), the plugin check of a
/// library the release build makes and `api-docs` (which writes into
/// `docs/`) are left out, and counted.
#[test]
fn the_readmes_commands_run() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let out = crate::common::scratch("docs", "readme");
    let mut in_sh = false;
    let (mut ran, mut left) = (0, 0);
    for line in readme.lines() {
        if line.starts_with("```") {
            in_sh = line == "```sh";
            continue;
        }
        let Some(command) = in_sh
            .then(|| line.strip_prefix("cargo run --release -- "))
            .flatten()
        else {
            continue;
        };
        let command = command.split(" #").next().unwrap().trim();
        let placeholder = [
            "FAMILY",
            "SHOP",
            "LIB",
            "|",
            "[",
            "plugin-check",
            "api-docs",
        ];
        if placeholder.iter().any(|p| command.contains(p)) {
            left += 1;
            continue;
        }
        // The outputs into the scratch directory, never the repository's.
        let mut args: Vec<String> = command
            .split_whitespace()
            .map(|a| match a.strip_prefix("out/") {
                Some(rest) => out.join(rest).to_str().unwrap().to_owned(),
                None => a.to_owned(),
            })
            .collect();
        if args[0] == "run" && !args.iter().any(|a| a == "--out") {
            let stem = std::path::Path::new(&args[1])
                .file_stem()
                .unwrap()
                .to_owned();
            args.extend([
                "--out".to_owned(),
                out.join(stem).to_str().unwrap().to_owned(),
            ]);
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, _, err) = crate::common::pilgrim(&args);
        assert_eq!(code, 0, "README: {command}\n{err}");
        ran += 1;
    }
    assert!(ran >= 6 && left <= 6, "{ran} commands ran, {left} left out");
}

#[test]
fn the_readme_is_short_and_the_docs_link_both_ways() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(
        lines <= 150,
        "README.md is {lines} lines: the manual belongs in docs/"
    );
    let pages: Vec<String> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".md"))
        .collect();
    assert!(pages.len() >= 8, "{pages:?}");
    let from_readme = links(&readme);
    for page in &pages {
        assert!(
            from_readme.iter().any(|l| l == &format!("docs/{page}")),
            "README.md does not link docs/{page}"
        );
        let text = std::fs::read_to_string(root().join("docs").join(page)).unwrap();
        // The generated API reference links the guide that links it.
        if page != "script-api.md" {
            assert!(
                links(&text).iter().any(|l| l == "../README.md"),
                "docs/{page} does not link back to the README"
            );
        }
    }
    let mut checked = 0;
    for file in ["README.md", "CHANGELOG.md", "benches/README.md"]
        .into_iter()
        .map(str::to_owned)
        .chain(pages.iter().map(|p| format!("docs/{p}")))
    {
        let text = std::fs::read_to_string(root().join(&file)).unwrap();
        let dir = Path::new(&file).parent().unwrap();
        for l in links(&text) {
            assert!(
                root().join(dir).join(&l).exists(),
                "{file} links {l}, which is not there"
            );
            checked += 1;
        }
    }
    assert!(checked > 30, "{checked} links");
}

/// The figures the docs quote of the default mandrel's passes are the
/// default run's: its roughing feed, feed a revolution, the stock each
/// roughing pass leaves and its ridge, as `docs/verification.md` and
/// `docs/families.md` say them.
#[test]
fn the_docs_quote_the_default_mandrels_figures() {
    let out = crate::common::default_run("docs", "mandrel", "figures");
    let report = crate::common::report_of(&out);
    let passes = report["verification"]["passes"].as_array().unwrap();
    let (rough, finish) = passes.split_at(passes.len() - 1);
    let num = |p: &serde_json::Value, k: &str| p[k].as_f64().unwrap();
    let stock: Vec<String> = rough
        .iter()
        .map(|p| {
            let name = p["name"].as_str().unwrap();
            let um = name
                .rsplit("stock ")
                .next()
                .unwrap()
                .trim_end_matches(" um");
            format!("{}", um.parse::<f64>().unwrap())
        })
        .collect();
    let said = format!(
        "the roughing passes at {} mm/min ({:.2} mm a revolution) leave {} um of stock under ridges of {:.0} um, and the finish at {} mm/min ({:.3} mm a revolution",
        num(&rough[0], "feed_mm_min"),
        num(&rough[0], "feed_per_rev_mm"),
        stock.join(", "),
        num(&rough[0], "ridge_mm") * 1e3,
        num(&finish[0], "feed_mm_min"),
        num(&finish[0], "feed_per_rev_mm"),
    );
    for page in ["docs/verification.md", "docs/families.md"] {
        let text = std::fs::read_to_string(crate::common::root().join(page)).unwrap();
        let flat = text.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(flat.contains(&said), "{page} must say: {said}");
    }
}

/// The script reference speaks the script's language: every function has
/// its doc, and no type is shown by its Rust path.
#[test]
fn the_script_reference_documents_everything_in_script_terms() {
    let text = std::fs::read_to_string(crate::common::root().join("docs/script-api.md")).unwrap();
    let undocumented: Vec<&str> = text
        .split("\n### ")
        .filter(|s| s.contains("(undocumented)"))
        .filter_map(|s| s.lines().next())
        .collect();
    assert!(undocumented.is_empty(), "{undocumented:#?}");
    let rust: Vec<&str> = text.lines().filter(|l| l.contains("crate::")).collect();
    assert!(rust.is_empty(), "{rust:#?}");
}
