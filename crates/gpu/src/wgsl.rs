//! The WGSL files and what each needs: a shader module is a file composed after every file it
//! needs ([`module`]), so that no file relies on names that happen to be pasted before it.
//! A test holds each file's list to what it uses: every name it uses that another file declares
//! comes from a file it lists, and it lists no file it does not use.

/// A WGSL file: its path under `crates/gpu/src`, its source and the files whose declarations it
/// uses.
#[derive(Debug)]
pub struct Wgsl {
    pub file: &'static str,
    pub source: &'static str,
    pub needs: &'static [&'static Wgsl],
}

macro_rules! wgsl {
    ($file:literal, [$($need:ident),* $(,)?]) => {
        Wgsl { file: $file, source: include_str!($file), needs: &[$(&$need),*] }
    };
}

/// The MERL table's nearest lookup (group 0, bindings 0 and 1) and the constants every module
/// shares (`PI`, `HALF_PI`).
pub static MERL_LOOKUP: Wgsl = wgsl!("merl_lookup.wgsl", []);
/// The lookup's batch entry point for the tests (`MerlLookup`).
pub static MERL_LOOKUP_BATCH: Wgsl = wgsl!("merl_lookup_batch.wgsl", [MERL_LOOKUP]);
/// The wavelet BRDF decoder and `material_brdf`, the BRDF the estimators read.
pub static WAVELET_BRDF: Wgsl = wgsl!("wavelet_brdf.wgsl", [MERL_LOOKUP]);
/// The raster pass, a module of its own.
pub static PREVIEW_RASTER: Wgsl = wgsl!("preview_raster.wgsl", []);
/// The shading module's constants, groups 1 and 2 and its dispatch order.
pub static PREVIEW_BINDINGS: Wgsl = wgsl!("preview_bindings.wgsl", []);
/// The estimators' sampling.
pub static PREVIEW_SAMPLING: Wgsl = wgsl!("preview_sampling.wgsl", [MERL_LOOKUP, PREVIEW_BINDINGS]);
/// What covers a pixel, its shading frame and its camera ray.
pub static PREVIEW_GEOMETRY: Wgsl = wgsl!("preview_geometry.wgsl", [PREVIEW_BINDINGS]);
/// The environment's lookups.
pub static PREVIEW_ENVIRONMENT: Wgsl =
    wgsl!("preview_environment.wgsl", [MERL_LOOKUP, PREVIEW_BINDINGS, PREVIEW_GEOMETRY]);
/// The shading pass's entry points.
pub static PREVIEW_SHADE: Wgsl = wgsl!(
    "preview_shade.wgsl",
    [MERL_LOOKUP, WAVELET_BRDF, PREVIEW_BINDINGS, PREVIEW_SAMPLING, PREVIEW_GEOMETRY, PREVIEW_ENVIRONMENT]
);
/// An adaptive frame, a file per stage of `render::adaptive` named as its Rust twin there
/// (`predict.rs`: `predict.wgsl`), beside the host side in `preview/adaptive/`. The prediction.
pub static ADAPTIVE_PREDICT: Wgsl = wgsl!(
    "preview/adaptive/predict.wgsl",
    [MERL_LOOKUP, WAVELET_BRDF, PREVIEW_BINDINGS, PREVIEW_SAMPLING, PREVIEW_GEOMETRY, PREVIEW_ENVIRONMENT]
);
/// The frame's state after its prediction, which the stages below share.
pub static ADAPTIVE_STATE: Wgsl = wgsl!("preview/adaptive/state.wgsl", []);
/// The pyramids and the plan.
pub static ADAPTIVE_PLAN: Wgsl = wgsl!("preview/adaptive/plan.wgsl", [PREVIEW_BINDINGS, ADAPTIVE_STATE]);
/// The samples and the list of shaded blocks.
pub static ADAPTIVE_SAMPLES: Wgsl =
    wgsl!("preview/adaptive/samples.wgsl", [PREVIEW_BINDINGS, PREVIEW_GEOMETRY, ADAPTIVE_STATE]);
/// The shaded blocks in place, the up-sampling and the output.
pub static ADAPTIVE_FRAME: Wgsl = wgsl!("preview/adaptive/frame.wgsl", [PREVIEW_BINDINGS, ADAPTIVE_STATE]);
/// The present pass, a module of its own.
pub static PREVIEW_PRESENT: Wgsl = wgsl!("preview_present.wgsl", []);

/// The files that are modules of their own (they bind their own resources under names the shading
/// module uses too).
pub static SEPARATE: [&Wgsl; 2] = [&PREVIEW_RASTER, &PREVIEW_PRESENT];

/// Every file, for the tests.
pub static ALL: [&Wgsl; 15] = [
    &MERL_LOOKUP,
    &MERL_LOOKUP_BATCH,
    &WAVELET_BRDF,
    &PREVIEW_RASTER,
    &PREVIEW_BINDINGS,
    &PREVIEW_SAMPLING,
    &PREVIEW_GEOMETRY,
    &PREVIEW_ENVIRONMENT,
    &PREVIEW_SHADE,
    &ADAPTIVE_PREDICT,
    &ADAPTIVE_STATE,
    &ADAPTIVE_PLAN,
    &ADAPTIVE_SAMPLES,
    &ADAPTIVE_FRAME,
    &PREVIEW_PRESENT,
];

/// The source of the shader module whose entry points are `roots`' : every file they need,
/// directly or not, each once and after the files it needs itself, then the roots.
pub fn module(roots: &[&Wgsl]) -> String {
    let mut order: Vec<&Wgsl> = Vec::new();
    for root in roots {
        root.visit(&mut order);
    }
    order.iter().map(|w| w.source).collect::<Vec<_>>().join("\n")
}

impl Wgsl {
    fn visit<'a>(&'a self, order: &mut Vec<&'a Wgsl>) {
        if order.iter().any(|w| w.file == self.file) {
            return;
        }
        for need in self.needs {
            need.visit(order);
        }
        order.push(self);
    }
}

#[cfg(test)]
mod tests {
    use std::collections::{BTreeMap, BTreeSet};

    use super::{ALL, SEPARATE, Wgsl};

    /// The source without comments.
    fn code(source: &str) -> String {
        source.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n")
    }

    /// The names a file declares at module scope: functions, structs, constants, overrides,
    /// aliases and variables.
    fn declared(source: &str) -> BTreeSet<String> {
        let mut names = BTreeSet::new();
        for line in code(source).lines().filter(|l| !l.starts_with(' ')) {
            let words: Vec<&str> =
                line.split(|c: char| !(c.is_alphanumeric() || c == '_')).filter(|w| !w.is_empty()).collect();
            let keyword = words.iter().position(|w| matches!(*w, "fn" | "struct" | "const" | "override" | "alias"));
            let keyword = keyword.or_else(|| {
                words.iter().position(|w| *w == "var").map(|i| {
                    // var<storage, read> name: skip the address space and access mode.
                    let after = &line[line.find("var").unwrap() + 3..];
                    let skipped = match after.starts_with('<') {
                        true => after[..after.find('>').unwrap()].split(',').count(),
                        false => 0,
                    };
                    i + skipped
                })
            });
            if let Some(k) = keyword {
                names.insert(words[k + 1].to_string());
            }
        }
        names
    }

    /// The names a file's code uses from module scope: every identifier but member accesses
    /// (`.name`), declarations of members and parameters (`name:`), and in a function its
    /// parameters and the names it declares with `let` or `var` (which shadow module scope).
    fn used(source: &str) -> BTreeSet<String> {
        let code = code(source);
        let mut uses = BTreeSet::new();
        let mut locals: BTreeSet<String> = BTreeSet::new();
        for line in code.lines() {
            if !line.starts_with(' ') && !line.starts_with('}') {
                locals.clear();
            }
            let tokens = tokens(line);
            for (k, (at, word)) in tokens.iter().enumerate() {
                let before = line[..*at].trim_end();
                let after = line[at + word.len()..].trim_start();
                let previous = k.checked_sub(1).map(|j| tokens[j].1.as_str());
                if matches!(previous, Some("let" | "var")) || (before.ends_with(['(', ',']) && after.starts_with(':')) {
                    locals.insert(word.clone());
                    continue;
                }
                if before.ends_with('.') || after.starts_with(':') || locals.contains(word) {
                    continue;
                }
                uses.insert(word.clone());
            }
        }
        uses
    }

    /// The identifiers of a line with their byte offsets.
    fn tokens(line: &str) -> Vec<(usize, String)> {
        let mut out = Vec::new();
        let mut start = None;
        for (i, c) in line.char_indices().chain([(line.len(), ' ')]) {
            let word = c.is_alphanumeric() || c == '_';
            match (word, start) {
                (true, None) => start = Some(i),
                (false, Some(s)) => {
                    if !line[s..i].starts_with(|c: char| c.is_ascii_digit()) {
                        out.push((s, line[s..i].to_string()));
                    }
                    start = None;
                }
                _ => {}
            }
        }
        out
    }

    /// For each file, the files whose declarations it uses, with the names it uses from each.
    fn actual_needs() -> BTreeMap<&'static str, BTreeMap<&'static str, Vec<String>>> {
        let separate = |w: &Wgsl| SEPARATE.iter().any(|s| s.file == w.file);
        let declarations: Vec<(&Wgsl, BTreeSet<String>)> = ALL.iter().map(|w| (*w, declared(w.source))).collect();
        ALL.iter()
            .map(|w| {
                let uses = used(w.source);
                let needs = declarations
                    .iter()
                    .filter(|(other, _)| other.file != w.file && !separate(w) && !separate(other))
                    .map(|(other, names)| (other.file, names.intersection(&uses).cloned().collect::<Vec<_>>()))
                    .filter(|(_, names)| !names.is_empty())
                    .collect();
                (w.file, needs)
            })
            .collect()
    }

    #[test]
    fn every_file_lists_exactly_the_files_it_uses() {
        let actual = actual_needs();
        let mut wrong = Vec::new();
        for w in ALL {
            let listed: BTreeSet<&str> = w.needs.iter().map(|n| n.file).collect();
            let uses: BTreeSet<&str> = actual[w.file].keys().copied().collect();
            if listed != uses {
                wrong.push(format!("{}: lists {listed:?}, uses {:?}", w.file, actual[w.file]));
            }
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    }

    /// No name is declared twice across the files a module composes (WGSL refuses it), and the
    /// declarations are read right: the shading module's entry points and a few names of each kind.
    #[test]
    fn declarations_are_unique_and_read_right() {
        let mut seen: BTreeMap<String, &str> = BTreeMap::new();
        let together =
            ALL.iter().filter(|w| w.file != "merl_lookup_batch.wgsl" && !SEPARATE.iter().any(|s| s.file == w.file));
        for w in together {
            for name in declared(w.source) {
                if let Some(other) = seen.insert(name.clone(), w.file) {
                    panic!("{name} is declared in {other} and {}", w.file);
                }
            }
        }
        let shade = declared(super::PREVIEW_SHADE.source);
        for name in ["shade_frame", "shade_backdrop", "shade_blocks", "estimate"] {
            assert!(shade.contains(name), "preview_shade.wgsl declares {name}: {shade:?}");
        }
        let bindings = declared(super::PREVIEW_BINDINGS.source);
        for name in ["Shade", "MODE_REFERENCE", "samples", "accumulation", "gbuffer_triangle"] {
            assert!(bindings.contains(name), "preview_bindings.wgsl declares {name}: {bindings:?}");
        }
    }

    /// Each function of a WGSL source (a line that starts with `fn NAME(`) with its comment
    /// block: the `//` and attribute lines directly above it, without their `//`, joined by
    /// spaces.
    fn function_comments(source: &str) -> Vec<(String, String)> {
        let lines: Vec<&str> = source.lines().collect();
        let mut out = Vec::new();
        for (i, line) in lines.iter().enumerate() {
            let Some(name) = line.strip_prefix("fn ").and_then(|rest| rest.split_once('(')).map(|(name, _)| name)
            else {
                continue;
            };
            let above = lines[..i].iter().rev().take_while(|l| l.starts_with("//") || l.starts_with('@'));
            let mut block: Vec<&str> = above.map(|l| l.trim_start_matches('/').trim()).collect();
            block.reverse();
            out.push((name.to_string(), block.join(" ")));
        }
        out
    }

    /// The paths a comment names in backticks: the leading `a::b::c` of every code span that
    /// starts with one.
    fn backticked_paths(comment: &str) -> Vec<Vec<String>> {
        comment
            .split('`')
            .skip(1)
            .step_by(2)
            .filter_map(|span| {
                let end = span.find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')).unwrap_or(span.len());
                let segments: Vec<String> = span[..end].split("::").map(str::to_string).collect();
                let words = segments.iter().all(|s| s.starts_with(|c: char| c.is_alphabetic() || c == '_'));
                (segments.len() > 1 && words).then_some(segments)
            })
            .collect()
    }

    /// The workspace's crates (`crates/<dir>`, named with `_` for `-`) with the names declared
    /// under their `src/`: items (`fn`, `struct`, `enum`, `const`, `static`, `type`, `trait`,
    /// `mod`), public fields (`pub name:`) and the modules that files and folders make.
    fn workspace_declarations() -> BTreeMap<String, BTreeSet<String>> {
        fn walk(dir: &std::path::Path, names: &mut BTreeSet<String>) {
            for entry in std::fs::read_dir(dir).unwrap().map(Result::unwrap) {
                let path = entry.path();
                let stem = path.file_stem().unwrap().to_string_lossy().to_string();
                if path.is_dir() {
                    names.insert(stem);
                    walk(&path, names);
                } else if path.extension().is_some_and(|e| e == "rs") {
                    names.insert(stem);
                    let code = code(&std::fs::read_to_string(&path).unwrap());
                    for line in code.lines() {
                        let words: Vec<String> = tokens(line).into_iter().map(|(_, w)| w).collect();
                        for pair in words.windows(2) {
                            let item = ["fn", "struct", "enum", "const", "static", "type", "trait", "mod"];
                            if item.contains(&pair[0].as_str()) {
                                names.insert(pair[1].clone());
                            }
                        }
                        let field = line.trim_start().strip_prefix("pub").map(|rest| {
                            let rest = rest.trim_start();
                            rest.strip_prefix('(').and_then(|r| r.split_once(')')).map_or(rest, |(_, r)| r.trim_start())
                        });
                        if let Some((name, _)) = field.and_then(|f| f.split_once(':'))
                            && !name.is_empty()
                            && name.chars().all(|c| c.is_alphanumeric() || c == '_')
                        {
                            names.insert(name.to_string());
                        }
                    }
                }
            }
        }
        let crates = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
        let mut out = BTreeMap::new();
        for entry in std::fs::read_dir(crates).unwrap().map(Result::unwrap) {
            let src = entry.path().join("src");
            if src.is_dir() {
                let mut names = BTreeSet::new();
                walk(&src, &mut names);
                out.insert(entry.file_name().to_string_lossy().replace('-', "_"), names);
            }
        }
        out
    }

    /// Every WGSL function names its CPU twin (a backticked path into a workspace crate, e.g.
    /// `` `render::pcg_hash` ``) in the comment block right above it, or says `No Rust twin:` and
    /// why; and every workspace path such a block names is declared in that crate, each segment
    /// after the crate's name (a path that starts with no crate's name, such as
    /// `Renderer::run_items`, is prose and not checked).
    #[test]
    fn every_wgsl_function_names_its_rust_twin_or_says_why_not() {
        let crates = workspace_declarations();
        assert!(crates.contains_key("render") && crates.contains_key("wavelet_brdf"), "crates: {:?}", crates.keys());
        let mut wrong = Vec::new();
        let mut functions = 0;
        for w in ALL {
            for (name, comment) in function_comments(w.source) {
                functions += 1;
                let paths = backticked_paths(&comment);
                let twins: Vec<&Vec<String>> = paths.iter().filter(|p| crates.contains_key(&p[0])).collect();
                if twins.is_empty() && !comment.contains("No Rust twin:") {
                    wrong.push(format!("{}: fn {name} names no Rust twin and does not say `No Rust twin:`", w.file));
                }
                for path in twins {
                    let declared = &crates[&path[0]];
                    if let Some(missing) = path[1..].iter().find(|s| !declared.contains(*s)) {
                        wrong.push(format!(
                            "{}: fn {name} names `{}`, but crates/{}/src declares no {missing}",
                            w.file,
                            path.join("::"),
                            path[0].replace('_', "-")
                        ));
                    }
                }
            }
        }
        assert!(functions > 100, "{functions} functions found");
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    }

    /// A module holds each file once, after the files it needs.
    #[test]
    fn a_module_composes_its_files_once_in_dependency_order() {
        let roots = [
            &super::PREVIEW_SHADE,
            &super::ADAPTIVE_PREDICT,
            &super::ADAPTIVE_PLAN,
            &super::ADAPTIVE_SAMPLES,
            &super::ADAPTIVE_FRAME,
        ];
        let source = super::module(&roots);
        let at = |w: &Wgsl| {
            assert_eq!(source.matches(w.source).count(), 1, "{} once", w.file);
            source.find(w.source).unwrap()
        };
        for w in ALL.iter().filter(|w| source.contains(w.source)) {
            for need in w.needs {
                assert!(at(need) < at(w), "{} after {}", w.file, need.file);
            }
        }
        assert!(source.ends_with(super::ADAPTIVE_FRAME.source));
        assert!(
            ALL.iter()
                .filter(|w| !SEPARATE.iter().any(|s| s.file == w.file))
                .all(|w| { w.file == "merl_lookup_batch.wgsl" || source.contains(w.source) })
        );
    }
}
