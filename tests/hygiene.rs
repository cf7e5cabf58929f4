//! The sources read as the compiler reads them (parsed with `syn`), for
//! what a review would otherwise have to find by eye: every small
//! tolerance named (a float literal below 1e-3 is a constant's value, in
//! `kernel/src/tolerance.rs` or beside the code that gives its meaning,
//! never a bare number in an expression); no public signature of the
//! kernel with a `String` error.

use proc_macro2::{TokenStream, TokenTree};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

/// The Rust sources that are not tests: the kernel's, the program's, the
/// plugins' and the ABI's. A module's tests in a file of their own are
/// `tests.rs` (declared `#[cfg(test)] mod tests;`), and left out.
fn sources() -> Vec<PathBuf> {
    let root = crate::common::root();
    let mut out = crate::common::files_with_ext(&root.join("kernel/src"), "rs");
    out.extend(crate::common::files_with_ext(&root.join("src"), "rs"));
    for e in std::fs::read_dir(root.join("plugins")).unwrap().flatten() {
        if e.path().join("src").is_dir() {
            out.extend(crate::common::files_with_ext(&e.path().join("src"), "rs"));
        }
    }
    out.retain(|f| f.file_name().is_none_or(|n| n != "tests.rs"));
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

/// The kernel's public items reachable from its root, parsed: each public
/// function's (and method's, trait method's, public function type's and
/// field's) error type, where it is `String`. An item is reachable where
/// every module on its way is `pub`, or where a `pub use` names it (or
/// globs its module).
#[derive(Default)]
struct StringErrors {
    path: Vec<String>,
    /// Whether every module on the current path is `pub`.
    open: Vec<bool>,
    /// (item's name for reachability, the module it is in, its label,
    /// reached through public modules).
    found: Vec<(String, String, String, bool)>,
    /// Names a `pub use` re-exports, and modules it globs.
    reexported: std::collections::BTreeSet<String>,
}

/// Whether `ty` is `Result<_, String>` (or a `fn(..) -> Result<_, String>`).
fn string_error(ty: &syn::Type) -> bool {
    match ty {
        syn::Type::Path(p) => {
            let Some(last) = p.path.segments.last() else {
                return false;
            };
            if last.ident != "Result" {
                return false;
            }
            let syn::PathArguments::AngleBracketed(args) = &last.arguments else {
                return false;
            };
            args.args.iter().nth(1).is_some_and(|a| {
                matches!(a, syn::GenericArgument::Type(syn::Type::Path(e))
                    if e.path.segments.last().is_some_and(|s| s.ident == "String"))
            })
        }
        syn::Type::BareFn(f) => match &f.output {
            syn::ReturnType::Type(_, t) => string_error(t),
            syn::ReturnType::Default => false,
        },
        _ => false,
    }
}

/// Whether a signature's output is a `String` error.
fn returns_string_error(sig: &syn::Signature) -> bool {
    matches!(&sig.output, syn::ReturnType::Type(_, t) if string_error(t))
}

fn is_pub(v: &syn::Visibility) -> bool {
    matches!(v, syn::Visibility::Public(_))
}

/// The names a `use` tree ends in (`*`: the module before it).
fn use_leaves(tree: &syn::UseTree, last: &str, out: &mut std::collections::BTreeSet<String>) {
    match tree {
        syn::UseTree::Path(p) => use_leaves(&p.tree, &p.ident.to_string(), out),
        syn::UseTree::Name(n) => {
            out.insert(n.ident.to_string());
        }
        syn::UseTree::Rename(r) => {
            out.insert(r.ident.to_string());
        }
        syn::UseTree::Glob(_) => {
            out.insert(format!("{last}::*"));
        }
        syn::UseTree::Group(g) => {
            for t in &g.items {
                use_leaves(t, last, out);
            }
        }
    }
}

impl StringErrors {
    fn note(&mut self, name: String, label: String) {
        let module = self.path.last().cloned().unwrap_or_default();
        let open = self.open.iter().all(|o| *o);
        let label = format!("{}::{label}", self.path.join("::"));
        self.found.push((name, module, label, open));
    }

    /// The items of a module (its folder `dir` for its children).
    fn items(&mut self, items: &[syn::Item], dir: &Path) {
        for item in items {
            match item {
                syn::Item::Use(u) if is_pub(&u.vis) => {
                    let mut leaves = std::collections::BTreeSet::new();
                    use_leaves(&u.tree, "", &mut leaves);
                    self.reexported.extend(leaves);
                }
                syn::Item::Fn(f)
                    if is_pub(&f.vis) && !is_test(&f.attrs) && returns_string_error(&f.sig) =>
                {
                    let n = f.sig.ident.to_string();
                    self.note(n.clone(), n);
                }
                syn::Item::Type(t) if is_pub(&t.vis) && string_error(&t.ty) => {
                    let n = t.ident.to_string();
                    self.note(n.clone(), n);
                }
                syn::Item::Impl(i) if i.trait_.is_none() => {
                    let ty = type_name(&i.self_ty);
                    for it in &i.items {
                        if let syn::ImplItem::Fn(f) = it {
                            if is_pub(&f.vis) && returns_string_error(&f.sig) {
                                self.note(ty.clone(), format!("{ty}::{}", f.sig.ident));
                            }
                        }
                    }
                }
                syn::Item::Trait(t) if is_pub(&t.vis) => {
                    for it in &t.items {
                        if let syn::TraitItem::Fn(f) = it {
                            if returns_string_error(&f.sig) {
                                self.note(
                                    t.ident.to_string(),
                                    format!("{}::{}", t.ident, f.sig.ident),
                                );
                            }
                        }
                    }
                }
                syn::Item::Struct(s) if is_pub(&s.vis) => {
                    for f in &s.fields {
                        if is_pub(&f.vis) && string_error(&f.ty) {
                            let name = f
                                .ident
                                .as_ref()
                                .map(ToString::to_string)
                                .unwrap_or_default();
                            self.note(s.ident.to_string(), format!("{}.{name}", s.ident));
                        }
                    }
                }
                syn::Item::Mod(m) if !is_test(&m.attrs) => {
                    let name = m.ident.to_string();
                    self.path.push(name.clone());
                    self.open.push(is_pub(&m.vis));
                    match &m.content {
                        Some((_, inner)) => self.items(inner, &dir.join(&name)),
                        None => {
                            let file = [
                                dir.join(format!("{name}.rs")),
                                dir.join(&name).join("mod.rs"),
                            ]
                            .into_iter()
                            .find(|p| p.is_file())
                            .unwrap_or_else(|| panic!("module {name} in {}", dir.display()));
                            let text = std::fs::read_to_string(&file).unwrap();
                            let parsed = syn::parse_file(&text).unwrap();
                            self.items(&parsed.items, &dir.join(&name));
                        }
                    }
                    self.open.pop();
                    self.path.pop();
                }
                _ => {}
            }
        }
    }

    /// The labels of the items a caller outside the crate reaches.
    fn reachable(&self) -> Vec<&str> {
        self.found
            .iter()
            .filter(|(name, module, _, open)| {
                *open
                    || self.reexported.contains(name)
                    || self.reexported.contains(&format!("{module}::*"))
            })
            .map(|(_, _, label, _)| label.as_str())
            .collect()
    }
}

/// A type's last name (an impl's self type).
fn type_name(t: &syn::Type) -> String {
    match t {
        syn::Type::Path(p) => p
            .path
            .segments
            .last()
            .map(|s| s.ident.to_string())
            .unwrap_or_default(),
        _ => "_".into(),
    }
}

/// No public function, method, trait method, function type, field or
/// alias reachable from the kernel's root has `String` as its error: every
/// failure a caller of the library meets is typed.
#[test]
fn no_public_signature_has_a_string_error() {
    let src = crate::common::root().join("kernel/src");
    let text = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    let mut v = StringErrors {
        path: vec!["pilgrim_kernel".into()],
        ..Default::default()
    };
    v.items(&syn::parse_file(&text).unwrap().items, &src);
    let found = v.reachable();
    assert!(
        found.is_empty(),
        "{} public signatures with a String error: {found:#?}",
        found.len()
    );
}

/// The kernel's [`Error`] carries its stages' typed errors: none of its
/// variants is a bare message (a single `String`).
#[test]
fn no_variant_of_the_kernels_error_is_a_bare_message() {
    let path = crate::common::root().join("kernel/src/error.rs");
    let file = syn::parse_file(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let error = (file.items.iter())
        .find_map(|i| match i {
            syn::Item::Enum(e) if e.ident == "Error" => Some(e),
            _ => None,
        })
        .expect("error.rs defines Error");
    let bare: Vec<String> = (error.variants.iter())
        .filter(|v| match &v.fields {
            syn::Fields::Unnamed(f) => {
                f.unnamed.len() == 1
                    && matches!(&f.unnamed[0].ty, syn::Type::Path(p) if p.path.is_ident("String"))
            }
            _ => false,
        })
        .map(|v| v.ident.to_string())
        .collect();
    assert!(error.variants.len() > 10, "{}", error.variants.len());
    assert!(
        bare.is_empty(),
        "Error's variants with a bare message: {bare:?}"
    );
}

/// Functions (free, in impls and in traits, outside tests) longer than
/// `limit` lines, as "file:line name (n lines)".
fn long_functions(files: &[PathBuf], limit: usize) -> Vec<String> {
    struct Long<'a> {
        file: &'a Path,
        limit: usize,
        found: Vec<String>,
    }
    impl Long<'_> {
        fn note(&mut self, name: &syn::Ident, block: &syn::Block) {
            use syn::spanned::Spanned;
            let span = block.span();
            let lines = span.end().line - span.start().line + 1;
            if lines > self.limit {
                self.found.push(format!(
                    "{}:{} {name} ({lines} lines)",
                    self.file.display(),
                    span.start().line
                ));
            }
        }
    }
    impl<'ast> Visit<'ast> for Long<'_> {
        fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
            if !is_test(&m.attrs) {
                syn::visit::visit_item_mod(self, m);
            }
        }
        fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
            if !is_test(&f.attrs) {
                self.note(&f.sig.ident, &f.block);
                syn::visit::visit_item_fn(self, f);
            }
        }
        fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
            self.note(&f.sig.ident, &f.block);
            syn::visit::visit_impl_item_fn(self, f);
        }
        fn visit_trait_item_fn(&mut self, f: &'ast syn::TraitItemFn) {
            if let Some(b) = &f.default {
                self.note(&f.sig.ident, b);
            }
            syn::visit::visit_trait_item_fn(self, f);
        }
    }
    let mut found = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(file).unwrap();
        let parsed = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let mut v = Long {
            file,
            limit,
            found: Vec::new(),
        };
        v.visit_file(&parsed);
        found.extend(v.found);
    }
    found
}

/// The run's stages, the page and each family read as a few screens of
/// code at a time: no function there is longer than 80 lines.
#[test]
fn no_long_function_in_the_run_the_page_or_a_family() {
    let src = crate::common::root().join("kernel/src");
    let mut files = Vec::new();
    for dir in ["job", "render", "families"] {
        files.extend(crate::common::files_with_ext(&src.join(dir), "rs"));
    }
    files.retain(|f| f.file_name().is_none_or(|n| n != "tests.rs"));
    assert!(files.len() > 30, "{files:?}");
    let long = long_functions(&files, 80);
    assert!(
        long.is_empty(),
        "{} functions over 80 lines:\n{long:#?}",
        long.len()
    );
}
