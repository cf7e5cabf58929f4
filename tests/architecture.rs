//! The kernel's module graph as `docs/architecture.md` describes it: the
//! top-level modules (a folder counts as one) and the arrows their code's
//! `crate::<module>` paths draw (comments and unit tests left out). No
//! circle; every arrow runs up the page's layer list; a family is named
//! only in its folder and the registry; the page's figures are the code's.

use crate::common::root;
use std::collections::{BTreeMap, BTreeSet};

/// Each top-level module of the kernel and the modules its code names.
fn graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = root().join("kernel/src");
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut stack = vec![src.clone()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            if p.extension().is_none_or(|x| x != "rs") {
                continue;
            }
            let rel = p.strip_prefix(&src).unwrap();
            let first = rel.iter().next().unwrap().to_str().unwrap();
            let module = first.trim_end_matches(".rs").to_owned();
            if module == "lib" {
                continue;
            }
            let text = std::fs::read_to_string(&p).unwrap();
            let code = text.split("#[cfg(test)]\nmod tests").next().unwrap();
            let names = out.entry(module.clone()).or_default();
            for line in code.lines().filter(|l| !l.trim_start().starts_with("//")) {
                for (i, _) in line.match_indices("crate::") {
                    let name: String = line[i + 7..]
                        .chars()
                        .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                        .collect();
                    if !name.is_empty() && name != module {
                        names.insert(name);
                    }
                }
            }
        }
    }
    let known: BTreeSet<String> = out.keys().cloned().collect();
    for names in out.values_mut() {
        names.retain(|n| known.contains(n));
    }
    out
}

#[test]
fn the_kernels_modules_form_no_circle() {
    let g = graph();
    assert!(g.len() > 20, "{g:?}");
    // Depth-first: a module met again while it is on the path closes a
    // circle.
    fn visit<'a>(
        m: &'a str,
        g: &'a BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<&'a str>,
        done: &mut BTreeSet<&'a str>,
    ) {
        if done.contains(m) {
            return;
        }
        if let Some(i) = path.iter().position(|p| *p == m) {
            panic!("an import circle: {} -> {m}", path[i..].join(" -> "));
        }
        path.push(m);
        for n in &g[m] {
            visit(n, g, path, done);
        }
        path.pop();
        done.insert(m);
    }
    let mut done = BTreeSet::new();
    for m in g.keys() {
        visit(m, &g, &mut Vec::new(), &mut done);
    }
}

/// The families under `kernel/src/families/`, each its folder.
fn families() -> Vec<String> {
    let mut out: Vec<String> = std::fs::read_dir(root().join("kernel/src/families"))
        .unwrap()
        .flatten()
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    out.sort();
    out
}

/// A family is its folder plus one registry line: no file outside
/// `families/<f>/` names `<f>` by its path (`families::<f>`), the
/// registry's (`families/mod.rs`) excepted; within the families, one
/// names another only where it is built on it (the worm is a thread
/// profile: `worm` uses `thread`).
#[test]
fn a_family_is_named_only_in_its_folder_and_the_registry() {
    let families = families();
    assert!(families.len() >= 4, "{families:?}");
    let built_on = [("worm", "thread")];
    let mut naming = vec![];
    let src = root().join("kernel/src");
    for file in crate::common::files_with_ext(&src, "rs") {
        let rel = file
            .strip_prefix(&src)
            .unwrap()
            .to_string_lossy()
            .into_owned();
        if rel == "families/mod.rs" {
            continue;
        }
        let own = rel
            .strip_prefix("families/")
            .and_then(|r| r.split('/').next())
            .map(str::to_owned);
        let text = std::fs::read_to_string(&file).unwrap();
        for f in &families {
            if own.as_deref() == Some(f.as_str())
                || own
                    .as_deref()
                    .is_some_and(|o| built_on.contains(&(o, f.as_str())))
            {
                continue;
            }
            let path = format!("families::{f}");
            let named = text.match_indices(&path).any(|(i, _)| {
                !text[i + path.len()..].starts_with(|c: char| c.is_alphanumeric() || c == '_')
            });
            if named {
                naming.push(format!("{rel} names {f}"));
            }
        }
    }
    assert!(naming.is_empty(), "{naming:#?}");
}

/// The layers `docs/architecture.md` lists ("Dependencies go one way, down
/// this list"), top first: each a set of modules, a name ending in a comma
/// going on to the next line's.
fn documented_layers() -> Vec<Vec<String>> {
    let page = std::fs::read_to_string(root().join("docs/architecture.md")).unwrap();
    let start = page
        .find("Dependencies go one way, down this list")
        .expect("the page's layer list");
    let mut layers: Vec<Vec<String>> = vec![];
    let mut open = false;
    for line in page[start..].lines().skip(2) {
        let Some(row) = line.strip_prefix("    ") else {
            break;
        };
        let names = row.get(..23).unwrap_or(row).trim();
        if names.is_empty() {
            continue;
        }
        let these: Vec<String> = names
            .split(',')
            .map(|n| n.trim().to_owned())
            .filter(|n| !n.is_empty())
            .collect();
        match layers.last_mut() {
            Some(last) if open => last.extend(these),
            _ => layers.push(these),
        }
        open = names.ends_with(',');
    }
    layers
}

/// Every module is in the page's list, and every arrow of the code runs
/// up it (to a module listed above, or beside it on its line): the page is
/// the code's order, not a wish.
#[test]
fn the_kernels_modules_keep_the_pages_order() {
    let g = graph();
    let layers = documented_layers();
    let level = |m: &str| layers.iter().position(|l| l.iter().any(|n| n == m));
    let unlisted: Vec<&String> = g.keys().filter(|m| level(m).is_none()).collect();
    assert!(unlisted.is_empty(), "not in the page's list: {unlisted:?}");
    let mut down = vec![];
    for (m, names) in &g {
        for n in names {
            if level(n) > level(m) {
                down.push(format!("{m} -> {n}"));
            }
        }
    }
    assert!(
        down.is_empty(),
        "arrows down the page's list (move the module or the code): {down:?}"
    );
}

/// The page says how many modules and arrows the graph has, as counted
/// here: the figures are the code's, never a wish or an old count.
#[test]
fn the_pages_figures_are_the_codes() {
    let g = graph();
    let arrows: usize = g.values().map(BTreeSet::len).sum();
    let said = format!("{} modules, {} arrows", g.len(), arrows);
    let page = std::fs::read_to_string(root().join("docs/architecture.md")).unwrap();
    let flat = page.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        flat.contains(&said),
        "docs/architecture.md must say '{said}' (run `cargo test --test pilgrim_e2e architecture::` for the figures)"
    );
    let abi = format!(
        "{}.{} (`ABI_MINOR`)",
        pilgrim_plugin_abi::ABI_MAJOR,
        pilgrim_plugin_abi::ABI_MINOR
    );
    assert!(
        flat.contains(&abi),
        "docs/architecture.md must give the ABI as {abi}"
    );
}
