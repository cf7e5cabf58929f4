//! The sources read as the compiler reads them (parsed with `syn`), for
//! what a review would otherwise have to find by eye: every small
//! tolerance named (a float literal below 1e-3 is a constant's value, in
//! `kernel/src/tolerance.rs` or beside the code that gives its meaning,
//! never a bare number in an expression).

use proc_macro2::{TokenStream, TokenTree};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// The Rust sources that are not tests: the kernel's, the program's, the
/// plugins' and the ABI's.
fn sources() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    let root = crate::common::root();
    let mut out = vec![];
    walk(&root.join("kernel/src"), &mut out);
    walk(&root.join("src"), &mut out);
    for e in std::fs::read_dir(root.join("plugins")).unwrap().flatten() {
        if e.path().join("src").is_dir() {
            walk(&e.path().join("src"), &mut out);
        }
    }
    out.sort();
    assert!(out.len() > 100, "{out:?}");
    out
}

/// Whether `attrs` mark test code (`#[cfg(test)]`, `#[test]`).
fn is_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("test")
            || (a.path().is_ident("cfg")
                && a.meta
                    .require_list()
                    .is_ok_and(|l| l.tokens.to_string() == "test"))
    })
}

/// The float literals below 1e-3 outside constants, with their lines.
#[derive(Default)]
struct SmallLiterals {
    in_const: usize,
    found: Vec<(usize, String)>,
}

impl SmallLiterals {
    fn check(&mut self, lit: &syn::LitFloat) {
        let Ok(v) = lit.base10_parse::<f64>() else {
            return;
        };
        if self.in_const == 0 && v > 0.0 && v < 1e-3 {
            self.found.push((lit.span().start().line, lit.to_string()));
        }
    }

    /// A macro's tokens (`format!`, `assert!`): its literals are read too.
    fn tokens(&mut self, tokens: TokenStream) {
        for t in tokens {
            match t {
                TokenTree::Literal(l) => {
                    if let Ok(f) = syn::parse_str::<syn::LitFloat>(&l.to_string()) {
                        let line = l.span().start().line;
                        let before = self.found.len();
                        self.check(&f);
                        for hit in &mut self.found[before..] {
                            hit.0 = line;
                        }
                    }
                }
                TokenTree::Group(g) => self.tokens(g.stream()),
                _ => {}
            }
        }
    }
}

impl<'ast> Visit<'ast> for SmallLiterals {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if !is_test(&m.attrs) {
            syn::visit::visit_item_mod(self, m);
        }
    }
    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        if !is_test(&f.attrs) {
            syn::visit::visit_item_fn(self, f);
        }
    }
    fn visit_item_const(&mut self, c: &'ast syn::ItemConst) {
        self.in_const += 1;
        syn::visit::visit_item_const(self, c);
        self.in_const -= 1;
    }
    fn visit_item_static(&mut self, c: &'ast syn::ItemStatic) {
        self.in_const += 1;
        syn::visit::visit_item_static(self, c);
        self.in_const -= 1;
    }
    fn visit_impl_item_const(&mut self, c: &'ast syn::ImplItemConst) {
        self.in_const += 1;
        syn::visit::visit_impl_item_const(self, c);
        self.in_const -= 1;
    }
    fn visit_lit_float(&mut self, lit: &'ast syn::LitFloat) {
        self.check(lit);
    }
    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        self.tokens(m.tokens.clone());
    }
}

/// No float literal below 1e-3 outside a constant, in any spelling
/// (`1e-9`, `1E-9`, `1e-9_f64`, `0.000_001`), outside tests.
#[test]
fn every_small_tolerance_is_named() {
    let mut bare = vec![];
    for path in sources() {
        let text = std::fs::read_to_string(&path).unwrap();
        let file = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut v = SmallLiterals::default();
        v.visit_file(&file);
        for (line, lit) in v.found {
            bare.push(format!("{}:{line}: {lit}", path.display()));
        }
    }
    assert!(
        bare.is_empty(),
        "float literals below 1e-3 outside a constant (name them in kernel/src/tolerance.rs or beside their code, saying why the value): {bare:#?}"
    );
}

/// The visitor finds what it is for, in every spelling, and passes a
/// constant's value and test code.
#[test]
fn the_literal_finder_finds_every_spelling() {
    let text = r#"
        const NAMED: f64 = 1e-9;
        fn f(x: f64) -> bool {
            let a = x < 1e-9 || x < 1E-9 || x < 1e-9_f64 || x < 0.000_001;
            assert!(x > 2e-7, "{}", 3e-8);
            a && x > 0.5
        }
        #[cfg(test)]
        mod tests { fn g() -> f64 { 1e-12 } }
    "#;
    let mut v = SmallLiterals::default();
    v.visit_file(&syn::parse_file(text).unwrap());
    let found: Vec<&str> = v.found.iter().map(|(_, l)| l.as_str()).collect();
    assert_eq!(
        found,
        ["1e-9", "1E-9", "1e-9_f64", "0.000_001", "2e-7", "3e-8"]
    );
}
