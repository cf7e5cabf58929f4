//! The kernel's module graph as `docs/architecture.md` describes it: the
//! top-level modules (a folder counts as one) and the arrows their code's
//! `crate::<module>` paths draw (comments and unit tests left out). No
//! circle; every arrow runs up the page's layer list; the generic modules
//! that name a family are the registry and the ones the page lists, and no
//! other.

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
    // The generic modules that name a family: the registry (by design),
    // and each of the others in the page's list of arrows still to go.
    let families = ["revolution", "caliber", "worm"];
    let naming: Vec<&str> = g
        .iter()
        .filter(|(m, names)| {
            !families.contains(&m.as_str()) && families.iter().any(|f| names.contains(*f))
        })
        .map(|(m, _)| m.as_str())
        .collect();
    assert_eq!(naming, ["families", "job"]);
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
