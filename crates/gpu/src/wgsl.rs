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
pub static PREVIEW_RASTER: Wgsl = wgsl!("preview/preview_raster.wgsl", []);
/// The shading module's constants, groups 1 and 2 and its dispatch order.
pub static PREVIEW_BINDINGS: Wgsl = wgsl!("preview/preview_bindings.wgsl", []);
/// The estimators' sampling.
pub static PREVIEW_SAMPLING: Wgsl = wgsl!("preview/preview_sampling.wgsl", [MERL_LOOKUP, PREVIEW_BINDINGS]);
/// What covers a pixel, its shading frame and its camera ray.
pub static PREVIEW_GEOMETRY: Wgsl = wgsl!("preview/preview_geometry.wgsl", [PREVIEW_BINDINGS]);
/// The environment's lookups.
pub static PREVIEW_ENVIRONMENT: Wgsl =
    wgsl!("preview/preview_environment.wgsl", [MERL_LOOKUP, PREVIEW_BINDINGS, PREVIEW_GEOMETRY]);
/// The shading pass's entry points.
pub static PREVIEW_SHADE: Wgsl = wgsl!(
    "preview/preview_shade.wgsl",
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
pub static PREVIEW_PRESENT: Wgsl = wgsl!("preview/preview_present.wgsl", []);

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
        for name in ["ShadeUniform", "MODE_REFERENCE", "samples", "accumulation", "gbuffer_triangle"] {
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

    /// A module of a workspace crate: the file that holds it and the folder of its child modules.
    struct Module {
        file: std::path::PathBuf,
        dir: std::path::PathBuf,
    }

    impl Module {
        /// The root module of workspace crate `name` (`_` for `-`), if there is one.
        fn root(name: &str) -> Option<Module> {
            let crates = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
            let src = crates.join(name.replace('_', "-")).join("src");
            src.join("lib.rs").is_file().then(|| Module { file: src.join("lib.rs"), dir: src })
        }

        /// Child module `name`: `name.rs` or `name/mod.rs` in the folder of child modules.
        fn child(&self, name: &str) -> Option<Module> {
            let file = self.dir.join(format!("{name}.rs"));
            let folder = self.dir.join(name);
            if file.is_file() {
                Some(Module { file, dir: folder })
            } else {
                let file = folder.join("mod.rs");
                file.is_file().then_some(Module { file, dir: folder })
            }
        }

        fn code(&self) -> String {
            code(&std::fs::read_to_string(&self.file).unwrap())
        }

        /// The file that declares item `name` in this module (a public one where `public`): here,
        /// or a public one in a child module it re-exports (`pub use child::*`,
        /// `pub(crate) use child::{..., name, ...}`).
        fn item(&self, name: &str, public: bool) -> Option<std::path::PathBuf> {
            let code = self.code();
            let item = ["fn", "struct", "enum", "const", "static", "type", "trait", "mod"];
            for line in code.lines() {
                let words: Vec<String> = tokens(line).into_iter().map(|(_, w)| w).collect();
                let declared = words.windows(2).any(|p| item.contains(&p[0].as_str()) && p[1] == name);
                if declared && (!public || line.trim_start().starts_with("pub")) {
                    return Some(self.file.clone());
                }
            }
            for statement in code.split(';') {
                let statement = statement.trim();
                let Some(used) = ["pub use ", "pub(crate) use ", "pub(super) use "]
                    .iter()
                    .find_map(|prefix| statement.strip_prefix(prefix))
                else {
                    continue;
                };
                let (path, names) = used.split_once("::{").map_or_else(
                    || used.rsplit_once("::").unwrap_or(("", used)),
                    |(path, list)| (path, list.trim_end_matches('}')),
                );
                let listed = names.split(',').map(|n| n.split(" as ").next().unwrap().trim());
                if !listed.clone().any(|n| n == "*" || n == name) {
                    continue;
                }
                let mut module = Some(Module { file: self.file.clone(), dir: self.dir.clone() });
                for segment in path.split("::").filter(|s| *s != "self") {
                    module = module.and_then(|m| m.child(segment));
                }
                if let Some(found) = module.and_then(|m| m.item(name, true)) {
                    return Some(found);
                }
            }
            None
        }
    }

    /// Whether `code` declares a member `name` of a type it declares: a method or associated
    /// constant (`fn name`, `const name`), a field (`name:`) or a variant (`name,`, `name {`,
    /// `name(`).
    fn declares_member(code: &str, name: &str) -> bool {
        code.lines().any(|line| {
            let words: Vec<String> = tokens(line).into_iter().map(|(_, w)| w).collect();
            let line = line.trim_start();
            let line = line.strip_prefix("pub").map_or(line, |rest| {
                let rest = rest.trim_start();
                rest.strip_prefix('(').and_then(|r| r.split_once(')')).map_or(rest, |(_, r)| r.trim_start())
            });
            words.windows(2).any(|p| matches!(p[0].as_str(), "fn" | "const" | "type") && p[1] == name)
                || line.strip_prefix(name).is_some_and(|rest| rest.starts_with([':', ',', '{', '(', ' ']))
        })
    }

    /// What a resolved path names.
    #[derive(Debug, PartialEq)]
    enum Resolved {
        Module,
        Item,
    }

    /// Resolves a path into a workspace crate (`crate::module::...::item`, then members of a
    /// type): each module a file of the crate, the item declared in the last one (or in a child
    /// module it re-exports), a member declared in the file that declares its type. `None` when
    /// the path starts with no workspace crate's name (prose, such as `Renderer::run_items`).
    fn resolve(path: &[String]) -> Option<Result<Resolved, String>> {
        let mut module = Module::root(&path[0])?;
        for (i, segment) in path.iter().enumerate().skip(1) {
            if let Some(child) = module.child(segment) {
                module = child;
                continue;
            }
            let Some(file) = module.item(segment, false) else {
                return Some(Err(format!("{} declares no {segment}", module.file.display())));
            };
            let code = code(&std::fs::read_to_string(&file).unwrap());
            return Some(match path[i + 1..].iter().find(|member| !declares_member(&code, member)) {
                Some(member) => Err(format!("{} declares no member {member} of {segment}", file.display())),
                None => Ok(Resolved::Item),
            });
        }
        Some(Ok(Resolved::Module))
    }

    /// Every WGSL function names its CPU twin (a backticked path to an item of a workspace
    /// crate, e.g. `` `render::pcg_hash` ``, not only a module) in the comment block right above
    /// it, or says `No Rust twin:` and why; and every workspace path such a block names resolves
    /// ([`resolve`]: its modules, the item, the members of a type).
    #[test]
    fn every_wgsl_function_names_its_rust_twin_or_says_why_not() {
        let mut wrong = Vec::new();
        let mut functions = 0;
        for w in ALL {
            for (name, comment) in function_comments(w.source) {
                functions += 1;
                let resolved: Vec<(Vec<String>, Result<Resolved, String>)> = backticked_paths(&comment)
                    .into_iter()
                    .filter_map(|path| resolve(&path).map(|r| (path, r)))
                    .collect();
                let twin = resolved.iter().any(|(_, r)| *r == Ok(Resolved::Item));
                if !twin && !comment.contains("No Rust twin:") {
                    wrong.push(format!(
                        "{}: fn {name} names no Rust function or item as its twin and does not say `No Rust twin:`",
                        w.file
                    ));
                }
                for (path, result) in resolved {
                    if let Err(e) = result {
                        wrong.push(format!("{}: fn {name} names `{}`, but {e}", w.file, path.join("::")));
                    }
                }
            }
        }
        assert!(functions > 100, "{functions} functions found");
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    }

    /// The three.js port's GLSL (`engines/three/src/shade.glsl.js`), function for function: each
    /// GLSL function is a WGSL function of the same name, or the comment block right above it
    /// names a twin (a Rust path to an item, or a WGSL function) or says `No twin:` and why; and
    /// every Rust path a comment block names resolves ([`resolve`]; the port names them without
    /// backticks, `envmap::geometry::uv`).
    #[test]
    fn every_glsl_function_of_the_three_js_port_names_its_twin() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../engines/three/src/shade.glsl.js");
        let glsl = std::fs::read_to_string(&path).unwrap();
        let wgsl: BTreeSet<String> =
            ALL.iter().flat_map(|w| function_comments(w.source)).map(|(name, _)| name).collect();
        let types = ["float", "vec2", "vec3", "vec4", "int", "uint", "bool", "void", "mat3", "uvec2", "ivec2"];
        let lines: Vec<&str> = glsl.lines().collect();
        let (mut wrong, mut functions) = (Vec::new(), 0);
        for (i, line) in lines.iter().enumerate() {
            let Some((ty, rest)) = line.split_once(' ') else { continue };
            let Some((name, _)) = rest.split_once('(') else { continue };
            if !types.contains(&ty) || !line.ends_with('{') || name == "main" {
                continue;
            }
            functions += 1;
            let above = lines[..i].iter().rev().take_while(|l| l.starts_with("//"));
            let mut block: Vec<&str> = above.map(|l| l.trim_start_matches('/').trim()).collect();
            block.reverse();
            let comment = block.join(" ");
            let paths: Vec<Vec<String>> = comment
                .split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .map(|word| word.trim_matches(':'))
                .filter(|word| word.contains("::"))
                .map(|word| word.split("::").map(str::to_string).collect())
                .collect();
            let mut twin = wgsl.contains(name) || comment.contains("No twin:");
            twin |= tokens(&comment).iter().any(|(_, word)| wgsl.contains(word));
            for path in paths {
                match resolve(&path) {
                    Some(Ok(resolved)) => twin |= resolved == Resolved::Item,
                    Some(Err(e)) => wrong.push(format!("{name} names `{}`, but {e}", path.join("::"))),
                    None => {}
                }
            }
            if !twin {
                wrong.push(format!("{name} is no WGSL function's name and names no twin (nor `No twin:`)"));
            }
        }
        assert!(functions > 40, "{functions} GLSL functions found in {}", path.display());
        assert!(wrong.is_empty(), "{}:\n{}", path.display(), wrong.join("\n"));
    }

    /// The resolver itself, on paths whose answers are known: a re-exported function, a private
    /// function by its module path, a type's method and field, a module, and three that do not
    /// resolve (a private function through a re-export among them).
    #[test]
    fn twin_paths_resolve_through_modules_and_re_exports() {
        let path = |p: &str| p.split("::").map(str::to_string).collect::<Vec<_>>();
        for good in [
            "render::adaptive::render_with",
            "render::adaptive::frame::upsample",
            "render::adaptive::Plan::compare",
            "render::Lighting::exponents",
        ] {
            assert_eq!(resolve(&path(good)), Some(Ok(Resolved::Item)), "{good}");
        }
        assert_eq!(resolve(&path("render::raster")), Some(Ok(Resolved::Module)));
        for bad in ["render::adaptive::upsample", "render::adaptive::Plan::no_such_method", "render::nowhere::pcg_hash"]
        {
            assert!(matches!(resolve(&path(bad)), Some(Err(_))), "{bad} resolved");
        }
        assert_eq!(resolve(&path("Renderer::run_items")), None);
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
