//! The house rules a reader of the repository relies on, checked on the tree itself
//! (docs/architecture.md):
//!
//! - no file in `src/` over [`MAX_FILE_LINES`] lines;
//! - no function over [`MAX_FN_LINES`] lines unless a comment at its top says why ("long
//!   because …");
//! - no `#[allow(clippy::too_many_arguments)]` without a `//` comment giving the reason on the
//!   line above it;
//! - no comment citing an issue number: a reader of the repository has no tracker, so a
//!   comment names the feature or the design-notes section instead;
//! - no import circle: two modules (files) that each use the other, directly or through
//!   others. A folder's `mod.rs` holds the folder's shared types, so a file's use of its own
//!   ancestors' `mod.rs` (`super::Solution`) is not counted; everything else is;
//! - the top-level modules form layers: no two of them use each other, directly or through
//!   others.

use regex::Regex;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Longest file in `src/`, in lines.
const MAX_FILE_LINES: usize = 800;
/// Longest function, in lines from its signature to its closing brace.
const MAX_FN_LINES: usize = 120;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every file below `dir` whose name ends with one of `exts`, as (path relative to the
/// repository, text), in path order.
fn files(dir: &Path, exts: &[&str]) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                if !p.ends_with("target") {
                    stack.push(p);
                }
            } else if exts.iter().any(|x| p.to_string_lossy().ends_with(x)) {
                if let Ok(text) = std::fs::read_to_string(&p) {
                    let rel = p.strip_prefix(root()).unwrap_or(&p);
                    out.push((rel.to_string_lossy().replace('\\', "/"), text));
                }
            }
        }
    }
    out.sort();
    out
}

fn rust_sources() -> Vec<(String, String)> {
    files(&root().join("src"), &[".rs"])
}

#[test]
fn no_file_in_src_is_over_800_lines() {
    let long: Vec<String> = rust_sources()
        .iter()
        .filter(|(_, t)| t.lines().count() > MAX_FILE_LINES)
        .map(|(p, t)| format!("{p}: {} lines", t.lines().count()))
        .collect();
    assert!(
        long.is_empty(),
        "files over {MAX_FILE_LINES} lines (split them by idea):\n{}",
        long.join("\n")
    );
}

/// Functions of a rustfmt-formatted file: (name, first line index, number of lines).
fn functions(text: &str) -> Vec<(String, usize, usize)> {
    let sig = Regex::new(r#"^(\s*)(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?(extern\s+"C"\s+)?fn\s+(\w+)"#).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, l) in lines.iter().enumerate() {
        let Some(c) = sig.captures(l) else { continue };
        let indent = c[1].len();
        // The line that opens the body (a declaration without one ends in `;`).
        let Some(k) = (i..lines.len()).find(|&k| {
            let t = lines[k].trim_end();
            t.ends_with('{') || t.ends_with("{}") || t.ends_with(';')
        }) else {
            continue;
        };
        let t = lines[k].trim_end();
        if t.ends_with(';') || t.ends_with("{}") {
            continue;
        }
        let close = format!("{}}}", " ".repeat(indent));
        if let Some(end) = (k + 1..lines.len()).find(|&e| lines[e].trim_end() == close) {
            out.push((c[8].to_string(), i, end - i + 1));
        }
    }
    out
}

/// Whether the comments just above line `i` (doc comments, attributes) or the first line of
/// the body say why the function is long.
fn says_why_long(lines: &[&str], i: usize) -> bool {
    let why = Regex::new(r"(?i)long because").unwrap();
    let above = lines[..i]
        .iter()
        .rev()
        .take_while(|l| {
            let t = l.trim_start();
            t.starts_with("//") || t.starts_with("#[")
        })
        .any(|l| why.is_match(l));
    let below = lines[i..]
        .iter()
        .skip_while(|l| !l.trim_end().ends_with('{'))
        .skip(1)
        .take_while(|l| l.trim_start().starts_with("//"))
        .any(|l| why.is_match(l));
    above || below
}

#[test]
fn no_function_is_over_120_lines_without_a_reason() {
    let mut long = Vec::new();
    for (p, t) in rust_sources() {
        let lines: Vec<&str> = t.lines().collect();
        for (name, i, n) in functions(&t) {
            if n > MAX_FN_LINES && !says_why_long(&lines, i) {
                long.push(format!("{p}:{}: fn {name}, {n} lines", i + 1));
            }
        }
    }
    assert!(
        long.is_empty(),
        "functions over {MAX_FN_LINES} lines with no \"long because …\" comment at their top:\n{}",
        long.join("\n")
    );
}

#[test]
fn every_too_many_arguments_allowance_gives_its_reason() {
    let why = Regex::new(r"(?i)\b(parameters|arguments)\b").unwrap();
    let mut bare = Vec::new();
    for (p, t) in rust_sources() {
        let lines: Vec<&str> = t.lines().collect();
        for (i, l) in lines.iter().enumerate() {
            if !l.contains("clippy::too_many_arguments") {
                continue;
            }
            let inline = l
                .split("too_many_arguments)]")
                .nth(1)
                .is_some_and(|r| r.contains("//"));
            // A plain comment on the line above, or a doc comment just above that says why.
            let above = i > 0 && {
                let a = lines[i - 1].trim_start();
                a.starts_with("//") && !a.starts_with("///") && !a.starts_with("//!")
            };
            let doc = lines[..i]
                .iter()
                .rev()
                .take_while(|l| l.trim_start().starts_with("///"))
                .any(|l| why.is_match(l));
            let above = above || doc;
            if !(inline || above) {
                bare.push(format!("{p}:{}", i + 1));
            }
        }
    }
    assert!(
        bare.is_empty(),
        "too_many_arguments allowed with no reason (a `//` comment on the line above, or the doc comment saying why so many parameters):\n{}",
        bare.join("\n")
    );
}

#[test]
fn no_comment_cites_an_issue_number() {
    let cite = Regex::new(r"(?i)\bissues?\s+#?\d+\b|(^|[\s(\[])#\d{1,4}\b").unwrap();
    let mut found = Vec::new();
    let mut all = rust_sources();
    all.extend(files(&root().join("tests"), &[".rs"]));
    all.extend(files(&root().join("scripts"), &[".py", ".sh"]));
    all.extend(files(&root().join("fuzz"), &[".rs"]));
    all.extend(files(&root().join("benches"), &[".rs"]));
    all.extend(
        files(&root(), &["build.rs", "setup.sh"])
            .into_iter()
            .filter(|(p, _)| !p.contains('/')),
    );
    for (p, t) in all {
        for (i, l) in t.lines().enumerate() {
            // Rust: the comment part of the line; Python and shell: the whole line, since
            // their comments and docstrings are hard to tell from code by eye alone.
            let text = if p.ends_with(".rs") {
                match l.find("//") {
                    Some(k) => &l[k..],
                    None => continue,
                }
            } else {
                l
            };
            let text = if p.ends_with(".rs") {
                text
            } else {
                text.trim_start_matches('#')
            };
            if cite.is_match(text) {
                found.push(format!("{p}:{}: {}", i + 1, l.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "comments citing an issue number (name the feature or docs/design.md §N):\n{}",
        found.join("\n")
    );
}

/// The module path of a source file of the crate rooted at `root_file` (`src/lib.rs` or a
/// binary's `main.rs`): `src/solve/books.rs` is `["solve", "books"]`.
fn module_of(file: &str, crate_dir: &str) -> Vec<String> {
    let rel = file
        .strip_prefix(crate_dir)
        .unwrap_or(file)
        .trim_start_matches('/');
    let rel = rel.trim_end_matches(".rs");
    let mut parts: Vec<String> = rel.split('/').map(str::to_string).collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// `a::{b::C, d::{e, f}}` → `a::b::C`, `a::d::e`, `a::d::f`.
fn expand(tree: &str) -> Vec<String> {
    let tree: String = tree.chars().filter(|c| !c.is_whitespace()).collect();
    fn go(prefix: &str, s: &str, out: &mut Vec<String>) {
        match s.find('{') {
            None => out.push(format!("{prefix}{s}")),
            Some(open) => {
                let head = &s[..open];
                let inner = &s[open + 1..s.len().saturating_sub(1)];
                // Split the inner list at top-level commas.
                let (mut depth, mut start) = (0, 0);
                for (k, c) in inner.char_indices() {
                    match c {
                        '{' => depth += 1,
                        '}' => depth -= 1,
                        ',' if depth == 0 => {
                            go(&format!("{prefix}{head}"), &inner[start..k], out);
                            start = k + 1;
                        }
                        _ => {}
                    }
                }
                if start < inner.len() {
                    go(&format!("{prefix}{head}"), &inner[start..], out);
                }
            }
        }
    }
    let mut out = Vec::new();
    go("", &tree, &mut out);
    out
}

/// Files of one crate and the modules each uses: an edge a → b where file a names a path into
/// module b (in a `use` or in code), but b is one of a's own ancestors.
fn module_edges(
    crate_dir: &str,
    sources: &[(String, String)],
) -> BTreeMap<String, BTreeSet<String>> {
    let modules: BTreeMap<Vec<String>, String> = sources
        .iter()
        .map(|(p, _)| (module_of(p, crate_dir), p.clone()))
        .collect();
    let use_start = Regex::new(r"^\s*(pub(\([^)]*\))?\s+)?use\s+").unwrap();
    let inline = Regex::new(r"\b(crate|super|self)((?:::\w+)+)").unwrap();
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (file, text) in sources {
        let me = module_of(file, crate_dir);
        let mut paths = Vec::new();
        let mut pending: Option<String> = None;
        let mut lines = text.lines().peekable();
        while let Some(l) = lines.next() {
            // Unit tests at the end of a file are not part of the module's design.
            if l.starts_with("#[cfg(test)]") && lines.peek().is_some_and(|n| n.starts_with("mod "))
            {
                break;
            }
            let code = match l.find("//") {
                Some(k) => &l[..k],
                None => l,
            };
            if let Some(p) = pending.as_mut() {
                p.push_str(code);
                if code.contains(';') {
                    paths.extend(expand(p.trim_end_matches(';')));
                    pending = None;
                }
                continue;
            }
            if let Some(m) = use_start.find(code) {
                let rest = &code[m.end()..];
                if rest.contains(';') {
                    paths.extend(expand(rest.split(';').next().unwrap_or("")));
                } else {
                    pending = Some(rest.to_string());
                }
                continue;
            }
            for c in inline.captures_iter(code) {
                paths.push(format!("{}{}", &c[1], &c[2]));
            }
        }
        for path in paths {
            let segs: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
            let mut at: Vec<String> = match segs.first() {
                Some(&"crate") => Vec::new(),
                Some(&"super") | Some(&"self") => me.clone(),
                _ => continue, // another crate
            };
            let mut rest = &segs[1..];
            if segs[0] == "super" {
                at.pop();
            }
            while rest.first() == Some(&"super") {
                at.pop();
                rest = &rest[1..];
            }
            // The longest prefix of the path that is a module of this crate.
            let mut target = at.clone();
            for s in rest {
                let mut next = target.clone();
                next.push(s.to_string());
                if modules.contains_key(&next) {
                    target = next;
                } else {
                    break;
                }
            }
            let is_ancestor = target.len() <= me.len() && me[..target.len()] == target[..];
            if is_ancestor {
                continue;
            }
            if let Some(t) = modules.get(&target) {
                edges.entry(file.clone()).or_default().insert(t.clone());
            }
        }
    }
    edges
}

/// Strongly connected components with more than one file (Tarjan).
fn cycles(edges: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct T<'a> {
        edges: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a str) {
        let n = t.index.len();
        t.index.insert(v, n);
        t.low.insert(v, n);
        t.stack.push(v);
        t.on.insert(v);
        if let Some(ws) = t.edges.get(v) {
            for w in ws {
                let w = w.as_str();
                if !t.index.contains_key(w) {
                    visit(t, w);
                    let lw = t.low[w];
                    let lv = t.low[v];
                    t.low.insert(v, lv.min(lw));
                } else if t.on.contains(w) {
                    let iw = t.index[w];
                    let lv = t.low[v];
                    t.low.insert(v, lv.min(iw));
                }
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.remove(w);
                comp.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in edges.keys() {
        if !t.index.contains_key(v.as_str()) {
            visit(&mut t, v);
        }
    }
    t.out
}

#[test]
fn no_import_circle() {
    let all = rust_sources();
    let mut report = Vec::new();
    let bin_dirs: BTreeSet<String> = all
        .iter()
        .filter(|(p, _)| p.starts_with("src/bin/") && p.ends_with("/main.rs"))
        .map(|(p, _)| p.trim_end_matches("/main.rs").to_string())
        .collect();
    let mut crates: Vec<(String, Vec<(String, String)>)> = vec![(
        "src".to_string(),
        all.iter()
            .filter(|(p, _)| !p.starts_with("src/bin/"))
            .cloned()
            .collect(),
    )];
    for d in bin_dirs {
        let prefix = format!("{d}/");
        crates.push((
            d.clone(),
            all.iter()
                .filter(|(p, _)| p.starts_with(&prefix))
                .cloned()
                .collect(),
        ));
    }
    for (dir, sources) in &crates {
        let edges = module_edges(dir, sources);
        for comp in cycles(&edges) {
            let inside: Vec<String> = comp
                .iter()
                .flat_map(|a| {
                    edges[a]
                        .iter()
                        .filter(|b| comp.contains(b))
                        .map(move |b| format!("  {a} → {b}"))
                })
                .collect();
            report.push(format!("{}:\n{}", comp.join(", "), inside.join("\n")));
        }
    }
    assert!(
        report.is_empty(),
        "import circles (modules that use each other):\n{}",
        report.join("\n")
    );
}

#[test]
fn the_checks_see_what_they_look_for() {
    // A function of 3 lines, one declaration, and a long one with its reason.
    let text = "fn a() {\n    1\n}\ntrait T {\n    fn b(&self);\n}\n";
    assert_eq!(functions(text), vec![("a".to_string(), 0, 3)]);
    let body: String = (0..130).map(|_| "    x();\n").collect();
    let long = format!("/// Long because it is one table.\nfn c() {{\n{body}}}\n");
    let lines: Vec<&str> = long.lines().collect();
    let f = functions(&long);
    assert_eq!(f[0].2, 132);
    assert!(says_why_long(&lines, f[0].1));
    // Use trees expand to every path.
    assert_eq!(
        expand("super::{a::B, c::{d, e}}"),
        vec!["super::a::B", "super::c::d", "super::c::e"]
    );
    // A two-file circle is found; an edge into an ancestor's mod.rs is not counted.
    let sources = vec![
        (
            "x/lib.rs".to_string(),
            "pub mod a;\npub mod b;\n".to_string(),
        ),
        (
            "x/a.rs".to_string(),
            "use crate::b::B;\nuse super::Root;\n".to_string(),
        ),
        (
            "x/b.rs".to_string(),
            "pub fn f() { crate::a::g() }\n".to_string(),
        ),
    ];
    let edges = module_edges("x", &sources);
    assert_eq!(
        cycles(&edges),
        vec![vec!["x/a.rs".to_string(), "x/b.rs".to_string()]]
    );
}

#[test]
fn top_level_modules_form_layers() {
    let all: Vec<(String, String)> = rust_sources()
        .into_iter()
        .filter(|(p, _)| !p.starts_with("src/bin/"))
        .collect();
    let edges = module_edges("src", &all);
    let top = |f: &str| -> String {
        let rel = f.trim_start_matches("src/");
        rel.split('/')
            .next()
            .unwrap()
            .trim_end_matches(".rs")
            .to_string()
    };
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut why: BTreeMap<(String, String), String> = BTreeMap::new();
    for (a, bs) in &edges {
        for b in bs {
            let (ta, tb) = (top(a), top(b));
            if ta != tb && ta != "lib" && tb != "lib" {
                g.entry(ta.clone()).or_default().insert(tb.clone());
                why.entry((ta, tb)).or_insert(format!("{a} → {b}"));
            }
        }
    }
    let comps = cycles(&g);
    let mut report = Vec::new();
    for c in comps {
        let mut inside = Vec::new();
        for a in &c {
            for b in g[a].iter().filter(|b| c.contains(b)) {
                inside.push(format!("  {a} → {b} ({})", why[&(a.clone(), b.clone())]));
            }
        }
        report.push(format!("{}:\n{}", c.join(", "), inside.join("\n")));
    }
    assert!(
        report.is_empty(),
        "top-level module circles:\n{}",
        report.join("\n")
    );
}
