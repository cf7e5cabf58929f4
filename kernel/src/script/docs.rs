//! The script API's reference, generated from the doc comments of the
//! functions registered (rhai's `metadata`), group by group.

use super::{api, register_types, Access};
use rhai::Engine;

/// A signature in the script writer's terms: script type names, no Rust
/// result wrapper, properties and indexing as they are written.
fn tidy(signature: &str) -> String {
    let mut s = signature.replace("&mut ", "");
    while let Some(i) = s.find("Result<") {
        let rest = &s[i + 7..];
        match rest.find(", Box<EvalAltResult>>") {
            Some(j) => s = format!("{}{}{}", &s[..i], &rest[..j], &rest[j + 21..]),
            None => break,
        }
    }
    for (rust, script) in [
        ("ToolpathHandle", "Toolpath"),
        ("Polyline", "Path"),
        ("RestSetup", "SteadyRest"),
        ("Numbers", "Floats"),
        ("String", "string"),
        ("Real", "float"),
        ("i64", "int"),
        ("&str", "string"),
        ("Map", "map"),
        ("Array", "array"),
        ("Table", "map"),
        ("()", "()"),
    ] {
        s = s.replace(rust, script);
    }
    if let Some(rest) = s.strip_prefix("get$") {
        // get$len(v: Floats) -> int  =>  v.len -> int (property)
        if let (Some(open), Some(close)) = (rest.find('('), rest.find(')')) {
            let arg = rest[open + 1..close]
                .split(':')
                .next()
                .unwrap_or("x")
                .trim();
            return format!("{arg}.{}{} (property)", &rest[..open], &rest[close + 1..]);
        }
    }
    if let Some(rest) = s.strip_prefix("index$get$") {
        // index$get$(v: Floats, i: int) -> float  =>  v[i] -> float
        if let (Some(comma), Some(close)) = (rest.find(','), rest.find(')')) {
            let v = rest[1..comma].split(':').next().unwrap_or("v").trim();
            let i = rest[comma + 1..close]
                .split(':')
                .next()
                .unwrap_or("i")
                .trim();
            return format!("{v}[{i}]{}", &rest[close + 1..]);
        }
    }
    s
}

/// Signature and doc comment of every function `engine` has, sorted by
/// name and signature (stable output).
fn entries(engine: &Engine) -> Vec<(String, String, Vec<String>)> {
    let json = engine.gen_fn_metadata_to_json(false).unwrap_or_default();
    let meta: serde_json::Value = serde_json::from_str(&json).unwrap_or_default();
    let mut entries: Vec<(String, String, Vec<String>)> = meta["functions"]
        .as_array()
        .map(|fs| {
            fs.iter()
                .filter_map(|f| {
                    let name = f["name"].as_str()?.to_owned();
                    let signature = f["signature"].as_str().unwrap_or(&name).to_owned();
                    let docs = f["docComments"]
                        .as_array()
                        .map(|d| {
                            d.iter()
                                .filter_map(|c| c.as_str().map(str::to_owned))
                                .collect()
                        })
                        .unwrap_or_default();
                    Some((name, signature, docs))
                })
                .collect()
        })
        .unwrap_or_default();
    entries.sort();
    entries.dedup();
    entries
}

/// The reference of every function the kernel gives scripts, as Markdown,
/// grouped as the API is (numbers, profiles, paths, ...): signature and
/// doc comment of each.
pub fn api_reference() -> String {
    let mut out = String::from(
        "# pilgrim script API\n\n\
         Generated from the kernel's doc comments by `pilgrim api-docs`; do not edit.\n\
         Where a function takes `Floats`, a plain array of numbers does as well. Operators\n\
         `+ - * /` combine `Floats` elementwise with `Floats` of the same length or with\n\
         numbers; unary `-` negates. The naming scheme and the family contract are in\n\
         `scripts/README.md`.\n",
    );
    for group in api() {
        let mut engine = Engine::new_raw();
        register_types(&mut engine);
        (group.register)(&mut engine, &Access::default());
        out.push_str(&format!("\n## {}\n", group.title));
        for (name, signature, docs) in entries(&engine) {
            if docs.is_empty() && !name.starts_with(|c: char| c.is_alphabetic()) {
                continue;
            }
            out.push_str(&format!("\n### `{}`\n\n", tidy(&signature)));
            let text: Vec<String> = docs
                .iter()
                .flat_map(|d| {
                    d.lines()
                        .map(|l| {
                            l.trim_start()
                                .trim_start_matches("///")
                                .strip_prefix(' ')
                                .unwrap_or(l.trim_start().trim_start_matches("///"))
                                .to_owned()
                        })
                        .collect::<Vec<_>>()
                })
                .collect();
            if text.is_empty() {
                out.push_str("(undocumented)\n");
            } else {
                out.push_str(&text.join("\n"));
                out.push('\n');
            }
        }
    }
    out
}
