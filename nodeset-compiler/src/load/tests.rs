//! The loader's unit tests: versions, header scans, files without `<Models>`, and the loader over generated
//! folder layouts (`layouts`).

use super::folders::{scan_header, Header, HEADER_LIMIT};
use super::*;

#[test]
fn versions_compare_numerically() {
    assert_eq!(cmp_version(Some("1.05.03"), Some("1.5.2")), Ordering::Greater);
    assert_eq!(cmp_version(Some("1.04"), Some("1.4.0")), Ordering::Equal);
    assert_eq!(cmp_version(Some("1.02"), Some("1.04.0")), Ordering::Less);
    assert_eq!(cmp_version(None, Some("1.0")), Ordering::Less);
    assert_eq!(cmp_version(Some("9.99.99"), Some("1.05")), Ordering::Greater);
}

#[test]
fn header_scan_stops_at_models_but_answers_as_the_full_prefix_would() {
    let dir = std::env::temp_dir().join(format!("nodeset-header-scan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = "<Model ModelUri=\"http://x/\" Version=\"1.0\" PublicationDate=\"2020-01-01\"/>";
    // A header past the first chunk, one that straddles chunks, one past the limit, and no UANodeSet.
    let pad = "<!--".to_string() + &"x".repeat(40_000) + "-->";
    // A file without <Models> answers with its first NamespaceUri (none when it has none).
    let uris = "<NamespaceUris><Uri>http://old/</Uri><Uri>http://other/</Uri></NamespaceUris>";
    let x = || vec![("http://x/".to_string(), Some("1.0".to_string()), Some("2020-01-01".to_string()))];
    let none = |own: Option<&str>| Some(Header { models: Vec::new(), own_namespace: own.map(str::to_string) });
    let cases = [
        (format!("<UANodeSet>{pad}<Models>{model}</Models></UANodeSet>"), Some(Header { models: x(), own_namespace: None })),
        (format!("<UANodeSet><Models>{pad}{model}</Models></UANodeSet>"), Some(Header { models: x(), own_namespace: None })),
        (format!("<UANodeSet>{}<Models>{model}</Models></UANodeSet>", "x".repeat(HEADER_LIMIT)), none(None)),
        (format!("<Other><Models>{model}</Models></Other>"), None),
        (format!("<UANodeSet>{uris}{pad}<UAObject NodeId=\"ns=1;i=1\"/></UANodeSet>"), none(Some("http://old/"))),
    ];
    for (i, (text, want)) in cases.iter().enumerate() {
        let path = dir.join(format!("{i}.xml"));
        std::fs::write(&path, text).unwrap();
        assert_eq!(&scan_header(&path), want, "case {i}");
    }
    // What a named file provides, for `verify`: the models it declares, or the one its first namespace
    // implies (an old ADI named beside the current one in a models folder must keep its namespace).
    assert_eq!(models_of_file(&dir.join("0.xml")), Some(vec!["http://x/".to_string()]));
    assert_eq!(models_of_file(&dir.join("4.xml")), Some(vec!["http://old/".to_string()]));
    assert_eq!(models_of_file(&dir.join("3.xml")), None);
    // Bytes that are not UTF-8, before `<Models>` and inside it: the scan searches the bytes, and reads the
    // element as lossy UTF-8 text (a replacement character where the bad byte was).
    let bad = dir.join("bad.xml");
    let mut bytes = b"<UANodeSet>\xFF\xE2<Models><Model ModelUri=\"http://x/\" Version=\"1.\xFF\"/></Models>".to_vec();
    bytes.extend_from_slice(b"</UANodeSet>");
    std::fs::write(&bad, &bytes).unwrap();
    let want = Header { models: vec![("http://x/".to_string(), Some("1.\u{FFFD}".to_string()), None)], own_namespace: None };
    assert_eq!(scan_header(&bad), Some(want));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A named file without `<Models>` implies one model per namespace it defines nodes in (numeric and
/// string NodeIds), in the order of its NamespaceUris; a namespace it only refers to implies none.
#[test]
fn a_file_without_models_implies_one_per_namespace_it_defines_nodes_in() {
    let text = r#"<UANodeSet xmlns="http://opcfoundation.org/UA/2011/03/UANodeSet.xsd">
  <NamespaceUris><Uri>http://a/</Uri><Uri>http://only-referenced/</Uri><Uri>http://b/</Uri></NamespaceUris>
  <UAObject NodeId="ns=3;s=Pump" BrowseName="3:Pump">
<References><Reference ReferenceType="HasTypeDefinition">i=58</Reference>
  <Reference ReferenceType="Organizes">ns=2;i=7</Reference></References>
  </UAObject>
  <UAObjectType NodeId="ns=1;i=1" BrowseName="1:ValveType">
<References><Reference ReferenceType="HasSubtype" IsForward="false">i=58</Reference></References>
  </UAObjectType>
</UANodeSet>"#;
    let mut diags = Diagnostics::new();
    let input = Input::Text { name: "implied.xml".into(), text: text.into() };
    let loaded = load(vec![input], &LoadOptions::default(), &mut diags);
    let implied: Vec<(&str, bool, bool)> =
        loaded.models.iter().map(|m| (m.uri.as_str(), m.version.is_none(), m.required.is_empty())).collect();
    assert_eq!(implied, vec![("http://a/", true, true), ("http://b/", true, true)]);
    let said = format!("{diags:?}");
    assert!(!said.contains("only-referenced"), "a namespace only referred to is looked for, not required: {said}");
}

/// A file without `<Models>` found in a models folder: an older file that refers to its namespace takes
/// it (from its own folder), not the newest model of that URI, and the namespace is its implied model.
#[test]
fn an_older_file_takes_the_older_file_of_its_folder_for_a_namespace_it_refers_to() {
    let dir = std::env::temp_dir().join(format!("nodeset-older-{}", std::process::id()));
    let file = |rel: &str, text: &str| {
        let p = dir.join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(&p, text).unwrap();
        p
    };
    let head = r#"<UANodeSet xmlns="http://opcfoundation.org/UA/2011/03/UANodeSet.xsd">"#;
    let object = r#"<UAObject NodeId="ns=1;i=1" BrowseName="1:X"><References><Reference ReferenceType="HasTypeDefinition">i=58</Reference></References></UAObject>"#;
    file(
        "current/A.xml",
        &format!(r#"{head}<NamespaceUris><Uri>http://a/</Uri></NamespaceUris><Models><Model ModelUri="http://a/" Version="2.0"/></Models>{object}</UANodeSet>"#),
    );
    let old_a = file("old/A.xml", &format!("{head}<NamespaceUris><Uri>http://a/</Uri></NamespaceUris>{object}</UANodeSet>"));
    let old_b = file(
        "old/B.xml",
        &format!("{head}<NamespaceUris><Uri>http://b/</Uri><Uri>http://a/</Uri></NamespaceUris>{object}</UANodeSet>"),
    );
    let mut diags = Diagnostics::new();
    let loaded = load(vec![Input::Path(old_b.clone())], &LoadOptions { model_dirs: vec![dir.clone()], ..Default::default() }, &mut diags);
    let mut paths: Vec<&Path> = loaded.files.iter().map(|f| loaded.sources.get(f.raw.file).path.as_path()).collect();
    paths.sort();
    assert_eq!(paths, vec![old_a.as_path(), old_b.as_path()]);
    let a = loaded.models.iter().find(|m| m.uri == "http://a/").expect("http://a/ is a model");
    assert_eq!((a.version.as_deref(), loaded.sources.get(a.file).path.as_path()), (None, old_a.as_path()));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn nearest_finds_typos_only() {
    let c = ["HasComponent", "HasProperty", "Organizes"];
    assert_eq!(nearest("HasComponnet", c.iter().copied()), Some("HasComponent"));
    assert_eq!(nearest("Zebra", c.iter().copied()), None);
    assert_eq!(edit_distance("kitten", "sitting"), 3);
    assert_eq!(edit_distance_within("kitten", "sitting", 2), None);
    assert_eq!(edit_distance_within("kitten", "sitting", 3), Some(3));
    assert_eq!(nearest(&"x".repeat(101), ["x".repeat(101).as_str()].into_iter()), None, "long names get no suggestion");
}

// ---- model folders: the loader ends, reads each file once, and says when files of one model differ ----------

/// How long one load may take before the test calls it hung (loads here take milliseconds).
const LIMIT: std::time::Duration = std::time::Duration::from_secs(10);

/// Runs `f` (a load) on a thread and returns its result, or fails if it takes longer than [`LIMIT`]. A loader
/// that never returns also never stops reading (the hang of issue 37 grew by 200 MB a second), so on a timeout
/// the whole test process ends at once instead of running on beside it.
fn within<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    match rx.recv_timeout(LIMIT) {
        Ok(v) => v,
        Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
            // Written past the test harness's capture, which would die with the process.
            use std::io::Write as _;
            let _ = writeln!(std::io::stderr(), "the loader did not return within {} s: {what}", LIMIT.as_secs());
            std::process::exit(101);
        }
        Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => panic!("the loader panicked: {what}"),
    }
}

/// A folder of NodeSet2 files for one test, removed afterwards.
struct Tree {
    dir: PathBuf,
}

impl Tree {
    fn new(name: &str) -> Tree {
        let dir = std::env::temp_dir().join(format!("nodeset-load-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Tree { dir }
    }

    fn file(&self, rel: &str, text: &str) -> PathBuf {
        let p = self.dir.join(rel);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(&p, text).unwrap();
        p
    }

    /// Loads the named files with this tree as the models folder, with a wall-clock guard.
    fn load(&self, named: &[PathBuf]) -> (Loaded, Diagnostics) {
        let (named, dir) = (named.to_vec(), self.dir.clone());
        let what = format!("{named:?} with --models {}", dir.display());
        within(&what, move || {
            let mut diags = Diagnostics::new();
            let inputs = named.into_iter().map(Input::Path).collect();
            let loaded = load(inputs, &LoadOptions { model_dirs: vec![dir], ..Default::default() }, &mut diags);
            (loaded, diags)
        })
    }
}

impl Drop for Tree {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

const HEAD: &str = r#"<UANodeSet xmlns="http://opcfoundation.org/UA/2011/03/UANodeSet.xsd">"#;

/// A base model with one node: the loader needs one, and the real one is 4 MB.
fn ns0() -> String {
    format!(
        r#"{HEAD}<Models><Model ModelUri="{NS0_URI}" Version="1.05.03" PublicationDate="2023-12-15T00:00:00Z"/></Models><UAObject NodeId="i=85" BrowseName="Objects"/></UANodeSet>"#
    )
}

/// A file declaring model `uri` (`version`, `date`), requiring `requires` (URI, lowest version), with
/// objects `ns=1;i=N` for each of `nodes`.
fn declared(uri: &str, version: &str, date: &str, requires: &[(String, Option<String>)], nodes: &[u32]) -> String {
    let uris: String = std::iter::once(uri.to_string()).chain(requires.iter().map(|r| r.0.clone())).map(|u| format!("<Uri>{u}</Uri>")).collect();
    let reqs: String = requires
        .iter()
        .map(|(u, v)| match v {
            Some(v) => format!(r#"<RequiredModel ModelUri="{u}" Version="{v}"/>"#),
            None => format!(r#"<RequiredModel ModelUri="{u}"/>"#),
        })
        .collect();
    let objects: String = nodes.iter().map(|n| format!(r#"<UAObject NodeId="ns=1;i={n}" BrowseName="1:N{n}"/>"#)).collect();
    format!(
        "{HEAD}<NamespaceUris>{uris}</NamespaceUris><Models><Model ModelUri=\"{uri}\" Version=\"{version}\" PublicationDate=\"{date}\">{reqs}</Model></Models>\n{objects}</UANodeSet>"
    )
}

/// A file without `<Models>` with these NamespaceUris, defining one object in namespace index `defines`.
fn bare(uris: &[String], defines: usize) -> String {
    let list: String = uris.iter().map(|u| format!("<Uri>{u}</Uri>")).collect();
    format!(r#"{HEAD}<NamespaceUris>{list}</NamespaceUris><UAObject NodeId="ns={defines};i=1" BrowseName="{defines}:Thing"/></UANodeSet>"#)
}

fn codes(diags: &Diagnostics) -> Vec<&'static str> {
    diags.items.iter().map(|d| d.code.as_str()).collect()
}

fn loaded_paths(loaded: &Loaded) -> Vec<PathBuf> {
    loaded.files.iter().map(|f| loaded.sources.get(f.raw.file).path.clone()).collect()
}

/// Issue 37, item 7: `check FILE --models DIR` with FILE in DIR, FILE without `<Models>` and with two
/// NamespaceUris, the first of which it only refers to: the loader found FILE itself in the folder as that
/// namespace's file, read it again, and again, without end.
#[test]
fn a_named_file_without_models_found_again_in_the_folder_is_read_once() {
    let tree = Tree::new("named-in-folder");
    tree.file("Opc.Ua.NodeSet2.xml", &ns0());
    let mine = tree.file("mine.xml", &bare(&["http://example.com/referenced/".into(), "http://example.com/mine/".into()], 2));
    // The same file again under another name: a copy is the same file, not a second model.
    tree.file("copies/mine-copy.xml", &bare(&["http://example.com/referenced/".into(), "http://example.com/mine/".into()], 2));
    let (loaded, diags) = tree.load(std::slice::from_ref(&mine));
    assert_eq!(loaded_paths(&loaded), vec![tree.dir.join("Opc.Ua.NodeSet2.xml"), mine.clone()], "{diags:?}");
    assert_eq!(codes(&diags), vec!["NS0109"], "{diags:?}");
    // Named through another path to the same folder: still once.
    let dotted = tree.dir.join(".").join("mine.xml");
    let (loaded, _) = tree.load(&[dotted]);
    assert_eq!(loaded.files.len(), 2);
}

/// Issue 37, item 3: files of the model folders that declare one model, version and date.
#[test]
fn files_of_one_model_version_and_date_are_one_model_only_when_their_content_is() {
    let uri = "http://example.com/robot/";
    let v = ("1.0", "2024-01-01T00:00:00Z");
    let user = |t: &Tree| t.file("user/user.xml", &declared("http://example.com/user/", "1.0", v.1, &[(uri.into(), Some("1.0".into()))], &[1]));
    let robot = |nodes: &[u32]| declared(uri, v.0, v.1, &[], nodes);

    // Byte-identical, and the same but for a byte order mark and CRLF line ends: one model, nothing said.
    let tree = Tree::new("dup-same");
    tree.file("Opc.Ua.NodeSet2.xml", &ns0());
    let a = tree.file("a/robot.xml", &robot(&[1, 2]));
    tree.file("b/robot.xml", &robot(&[1, 2]));
    tree.file("c/robot-saved-on-windows.xml", &format!("\u{feff}{}", robot(&[1, 2]).replace('\n', "\r\n")));
    let named = user(&tree);
    let (loaded, diags) = tree.load(std::slice::from_ref(&named));
    assert!(loaded_paths(&loaded).contains(&a), "the shorter path, then path order: a/ before b/");
    assert!(codes(&diags).is_empty(), "{diags:?}");

    // Different content, neither holding every node of the other: an error naming both files.
    let tree = Tree::new("dup-differ");
    tree.file("Opc.Ua.NodeSet2.xml", &ns0());
    let a = tree.file("a/robot.xml", &robot(&[1, 2]));
    let b = tree.file("b/robot.xml", &robot(&[1, 3]));
    let named = user(&tree);
    let (loaded, diags) = tree.load(std::slice::from_ref(&named));
    let d: Vec<&Diagnostic> = diags.items.iter().filter(|d| d.code == Code::AmbiguousModel).collect();
    assert_eq!(d.len(), 1, "{diags:?}");
    let all = format!("{} {}", d[0].message, d[0].notes.join(" "));
    assert!(all.contains(&a.display().to_string()) && all.contains(&b.display().to_string()), "names both files: {all}");
    assert!(d[0].help.as_deref().is_some_and(|h| h.contains("command line")), "says how to choose: {:?}", d[0].help);
    assert_eq!(d[0].span.map(|s| s.file), Some(loaded.files.last().unwrap().raw.file), "points at the requirement in user.xml");
    assert_eq!(d[0].labels.len(), 2, "a label at each file's <Model>: {:?}", d[0].labels);
    assert!(loaded_paths(&loaded).contains(&a), "the recovery reads the first by the folder rule");
    // Naming one of them chooses it, whichever, with nothing said.
    for chosen in [&a, &b] {
        let (loaded, diags) = tree.load(&[named.clone(), chosen.clone()]);
        assert!(codes(&diags).is_empty(), "{diags:?}");
        let robots: Vec<PathBuf> = loaded_paths(&loaded).into_iter().filter(|p| p.ends_with("robot.xml")).collect();
        assert_eq!(robots, vec![chosen.clone()]);
    }

    // One holds every node of the other and more: it is read, and a warning says so.
    let tree = Tree::new("dup-superset");
    tree.file("Opc.Ua.NodeSet2.xml", &ns0());
    let small = tree.file("a/robot.xml", &robot(&[1, 2]));
    let big = tree.file("b/robot-full.xml", &robot(&[1, 2, 3]));
    let named = user(&tree);
    let (loaded, diags) = tree.load(std::slice::from_ref(&named));
    let paths = loaded_paths(&loaded);
    assert!(paths.contains(&big) && !paths.contains(&small), "{paths:?}");
    assert_eq!(codes(&diags), vec!["NS0115"], "{diags:?}");
    assert!(diags.items[0].message.contains(&small.display().to_string()) && diags.items[0].message.contains(&big.display().to_string()));

    // Different versions of one model are not a tie: the newest is read, nothing said. So are different dates.
    let tree = Tree::new("dup-versions");
    tree.file("Opc.Ua.NodeSet2.xml", &ns0());
    tree.file("a/robot.xml", &robot(&[1]));
    let newer = tree.file("b/robot-1.1.xml", &declared(uri, "1.1", v.1, &[], &[7]));
    tree.file("c/robot-later.xml", &declared(uri, v.0, "2025-01-01T00:00:00Z", &[], &[8]));
    let named = user(&tree);
    let (loaded, diags) = tree.load(std::slice::from_ref(&named));
    assert!(loaded_paths(&loaded).contains(&newer));
    assert!(codes(&diags).is_empty(), "{diags:?}");
}

/// A deterministic source of choices for the layout generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 33) as usize % n
    }

    fn chance(&mut self, percent: usize) -> bool {
        self.below(100) < percent
    }
}

/// A generated file and what the generator put in it.
#[derive(Clone, Debug)]
struct GenFile {
    /// Relative to the layout's folder (`models/...` is in the models folder).
    rel: String,
    text: String,
    /// The declared model (URI, version, date), if any.
    model: Option<(String, String, String)>,
    requires: Vec<(String, Option<String>)>,
    /// For a file without `<Models>`: its NamespaceUris and the one it defines its node in.
    uris: Vec<String>,
    defines: Option<String>,
    nodes: Vec<u32>,
}

const DATE: &str = "2024-01-01T00:00:00Z";

/// One folder layout from `seed`: a base model, 2-4 models in one or two versions, each perhaps with a
/// copy (identical, saved with CRLF, different, or holding more nodes) elsewhere in the folder, random
/// requirements among them (cycles included, some on a missing model or a version that does not exist),
/// files without `<Models>` that refer to each other or to the models (some defining their node in their
/// second namespace, as the hang's file did), and one or two named files, most of them also in the folder.
fn layout(seed: u64) -> (Vec<GenFile>, Vec<String>) {
    let mut r = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let dirs = ["models/", "models/a/", "models/b/", "models/a/c/"];
    let k = 2 + r.below(3);
    let uri = |j: usize| format!("http://gen/m{j}/");
    let mut files = vec![GenFile {
        rel: "models/Opc.Ua.NodeSet2.xml".into(),
        text: ns0(),
        model: Some((NS0_URI.into(), "1.05.03".into(), "2023-12-15T00:00:00Z".into())),
        requires: Vec::new(),
        uris: Vec::new(),
        defines: None,
        nodes: Vec::new(),
    }];
    for j in 0..k {
        for version in if r.chance(30) { vec!["1.0", "2.0"] } else { vec!["1.0"] } {
            let mut requires = Vec::new();
            for other in (0..k).filter(|&o| o != j) {
                if r.chance(35) {
                    let v = [None, Some("1.0"), Some("9.0")][[0, 0, 1, 1, 2][r.below(5)]];
                    requires.push((uri(other), v.map(str::to_string)));
                }
            }
            if r.chance(15) {
                requires.push(("http://gen/missing/".into(), None));
            }
            let make = |nodes: &[u32], rel: String| GenFile {
                rel,
                text: declared(&uri(j), version, DATE, &requires, nodes),
                model: Some((uri(j), version.into(), DATE.into())),
                requires: requires.clone(),
                uris: Vec::new(),
                defines: None,
                nodes: nodes.to_vec(),
            };
            let main = make(&[1, 2], format!("{}m{j}-{version}.xml", dirs[r.below(dirs.len())]));
            let copy_rel = format!("{}copy-m{j}-{version}.xml", dirs[r.below(dirs.len())]);
            let copy = match r.below(8) {
                0 => Some(GenFile { rel: copy_rel, ..main.clone() }),
                1 => Some(GenFile { rel: copy_rel, text: format!("\u{feff}{}", main.text.replace('\n', "\r\n")), ..main.clone() }),
                2 => Some(make(&[1, 3], copy_rel)),
                3 => Some(make(&[1, 2, 3], copy_rel)),
                _ => None,
            };
            files.push(main);
            files.extend(copy);
        }
    }
    let bares = r.below(3);
    for t in 0..bares {
        let own = format!("http://gen/old{t}/");
        let other = if r.chance(50) { uri(r.below(k)) } else { format!("http://gen/old{}/", (t + 1) % bares) };
        let uris = if other == own { vec![own] } else { vec![own, other] };
        let defines = 1 + r.below(uris.len());
        files.push(GenFile {
            rel: format!("{}old{t}.xml", dirs[r.below(dirs.len())]),
            text: bare(&uris, defines),
            model: None,
            requires: Vec::new(),
            defines: Some(uris[defines - 1].clone()),
            uris,
            nodes: vec![1],
        });
    }
    // The named files: one or two, of different models, most of them in the folder, some outside it.
    let mut named: Vec<String> = Vec::new();
    let mut names_of: Vec<String> = Vec::new();
    for _ in 0..1 + r.below(2) {
        let f = files[1 + r.below(files.len() - 1)].clone();
        let name = f.model.as_ref().map(|m| m.0.clone()).or(f.defines.clone()).unwrap_or_default();
        if names_of.contains(&name) || named.contains(&f.rel) {
            continue;
        }
        names_of.push(name);
        if r.chance(25) {
            let outside = GenFile { rel: f.rel.replacen("models/", "outside/", 1), ..f };
            named.push(outside.rel.clone());
            files.push(outside);
        } else {
            named.push(f.rel);
        }
    }
    (files, named)
}

/// The loader over generated folder layouts: every load returns (within [`LIMIT`]), reads no file twice,
/// gives the same answer whatever the order of the named files, and its results and diagnostics agree with
/// what the generator put in the layout.
#[test]
fn the_loader_ends_and_answers_sensibly_on_generated_folder_layouts() {
    let tree = Tree::new("layouts");
    let mut seen_codes: BTreeSet<&str> = BTreeSet::new();
    for seed in 0..200u64 {
        let (files, named) = layout(seed);
        let root = tree.dir.join(format!("{seed}"));
        let mut by_path: BTreeMap<PathBuf, GenFile> = BTreeMap::new();
        for f in &files {
            let p = root.join(&f.rel);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(&p, &f.text).unwrap();
            by_path.insert(folders::canonical(&p), f.clone());
        }
        let named: Vec<PathBuf> = named.iter().map(|n| root.join(n)).collect();
        let models = root.join("models");
        let run = |named: Vec<PathBuf>| {
            let models = models.clone();
            within(&format!("seed {seed}: {named:?}"), move || {
                let mut diags = Diagnostics::new();
                let loaded = load(named.into_iter().map(Input::Path).collect(), &LoadOptions { model_dirs: vec![models], ..Default::default() }, &mut diags);
                (loaded, diags)
            })
        };
        let (loaded, diags) = run(named.clone());
        let ctx = format!("seed {seed}, named {named:?}\nfiles: {files:#?}\nloaded: {:?}\nsaid: {:#?}", loaded_paths(&loaded), diags.items);
        let said = |code: Code, uri: &str| diags.items.iter().any(|d| d.code == code && d.message.contains(uri));
        seen_codes.extend(codes(&diags));

        // Each file once: by path and by content; each named file loaded; each model once.
        let paths: Vec<PathBuf> = loaded_paths(&loaded).iter().map(|p| folders::canonical(p)).collect();
        assert_eq!(paths.iter().collect::<BTreeSet<_>>().len(), paths.len(), "a file read twice\n{ctx}");
        let texts: Vec<&str> = loaded.files.iter().map(|f| loaded.sources.get(f.raw.file).text.as_str()).collect();
        for (i, a) in texts.iter().enumerate() {
            assert!(!texts[..i].iter().any(|b| folders::same_content(a.as_bytes(), b.as_bytes())), "two copies loaded\n{ctx}");
        }
        for n in &named {
            assert!(paths.contains(&folders::canonical(n)), "named file {} not loaded\n{ctx}", n.display());
        }
        let uris: Vec<&str> = loaded.models.iter().map(|m| m.uri.as_str()).collect();
        assert_eq!(uris.iter().collect::<BTreeSet<_>>().len(), uris.len(), "a model loaded twice\n{ctx}");
        let gen = |p: &PathBuf| by_path.get(p).unwrap_or_else(|| panic!("{} was not generated\n{ctx}", p.display()));
        let is_named = |p: &PathBuf| named.iter().any(|n| folders::canonical(n) == *p);
        let folder_files: Vec<&GenFile> = files.iter().filter(|f| f.rel.starts_with("models/")).collect();

        for p in &paths {
            let f = gen(p);
            // A RequiredModel is loaded in a version that satisfies it, or the diagnostic says why not. (A
            // model implied by a named file without <Models> has no version, and satisfies any: NS0109.)
            for (uri, version) in &f.requires {
                match loaded.models.iter().find(|m| m.uri == *uri) {
                    Some(m) if m.version.is_some() && cmp_version(m.version.as_deref(), version.as_deref()) == Ordering::Less => {
                        assert!(said(Code::ModelTooOld, uri), "{uri} loaded too old, not said\n{ctx}")
                    }
                    Some(_) => {}
                    None => assert!(said(Code::MissingModel, uri) || said(Code::ModelTooOld, uri), "{uri} missing, not said\n{ctx}"),
                }
            }
            let Some((uri, version, date)) = &f.model else { continue };
            if is_named(p) {
                continue;
            }
            // A model read from the folder: no named file declares it, it is the newest there, and a
            // different file of the same version and date is never passed over in silence.
            assert!(!named.iter().any(|n| gen(&folders::canonical(n)).model.as_ref().is_some_and(|m| m.0 == *uri)), "named file lost\n{ctx}");
            let same_model: Vec<&&GenFile> = folder_files.iter().filter(|g| g.model.as_ref().is_some_and(|m| m.0 == *uri)).collect();
            let newest = same_model.iter().map(|g| g.model.as_ref().unwrap().1.as_str()).max_by(|a, b| cmp_version(Some(a), Some(b)));
            assert_eq!(newest, Some(version.as_str()), "not the newest version of {uri}\n{ctx}");
            let differing: Vec<&&&GenFile> = same_model
                .iter()
                .filter(|g| g.model.as_ref().is_some_and(|m| m.1 == *version && m.2 == *date))
                .filter(|g| !folders::same_content(g.text.as_bytes(), f.text.as_bytes()))
                .collect();
            let (ambiguous, superset) = (said(Code::AmbiguousModel, uri), said(Code::ModelFilesDiffer, uri));
            if differing.is_empty() {
                assert!(!ambiguous && !superset, "{uri}: copies are one model, nothing to say\n{ctx}");
            } else {
                assert!(ambiguous != superset, "{uri}: different files of one version and date, said once\n{ctx}");
                if superset {
                    assert!(differing.iter().all(|g| g.nodes.iter().all(|n| f.nodes.contains(n)) && g.nodes.len() < f.nodes.len()), "{ctx}");
                }
            }
        }

        // Requirements among the loaded files: a cycle is said, otherwise each file comes after those it needs.
        let provider: BTreeMap<&str, usize> =
            loaded.models.iter().map(|m| (m.uri.as_str(), loaded.files.iter().position(|f| f.raw.file == m.file).unwrap())).collect();
        let deps: Vec<BTreeSet<usize>> = paths
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let f = gen(p);
                let needs = f.requires.iter().map(|r| r.0.as_str()).chain(f.uris.iter().map(String::as_str).filter(|u| Some(*u) != f.defines.as_deref()));
                needs.chain([NS0_URI]).filter_map(|u| provider.get(u).copied()).filter(|&j| j != i).collect()
            })
            .collect();
        let mut done = vec![false; deps.len()];
        while let Some(i) = (0..deps.len()).find(|&i| !done[i] && deps[i].iter().all(|&d| done[d])) {
            done[i] = true;
        }
        let cyclic = done.contains(&false);
        assert_eq!(diags.items.iter().any(|d| d.code == Code::ModelCycle), cyclic, "a cycle is said exactly when there is one\n{ctx}");
        if !cyclic {
            for (i, d) in deps.iter().enumerate() {
                assert!(d.iter().all(|&j| j < i), "{} before a file it requires\n{ctx}", paths[i].display());
            }
        }

        // The order of the named files changes nothing.
        let (again, diags_again) = run(named.iter().rev().cloned().collect());
        assert_eq!(loaded_paths(&again), loaded_paths(&loaded), "{ctx}");
        let key = |d: &Diagnostics| {
            let mut v: Vec<(String, String)> = d.items.iter().map(|d| (d.code.as_str().to_string(), d.message.clone())).collect();
            v.sort();
            v
        };
        assert_eq!(key(&diags_again), key(&diags), "{ctx}");
    }
    // The layouts reach every situation the loader has a word for.
    for code in ["NS0101", "NS0102", "NS0105", "NS0109", "NS0114", "NS0115"] {
        assert!(seen_codes.contains(code), "no layout gave {code}: widen the generator ({seen_codes:?})");
    }
}

/// The loader finds copies of a file by the length of their normalised content, then compares bytes: a copy
/// with a byte order mark, CRLF line ends or both must have the same length as the original (else it would
/// be read as a second model), and the fast comparison must agree with the byte-by-byte definition.
#[test]
fn copies_have_one_normalised_length() {
    let bases = ["<a>\n<b/>\n</a>\n", "x\ry\r\n\r\nz", "\r", "\n\r\n\r", "", "<UANodeSet>\r\n\r</UANodeSet>"];
    let variants = |t: &str| -> Vec<Vec<u8>> {
        let crlf = t.replace("\r\n", "\n").replace('\n', "\r\n");
        let lf = t.replace("\r\n", "\n");
        [t.to_string(), crlf.clone(), lf.clone(), format!("\u{feff}{t}"), format!("\u{feff}{crlf}"), format!("\u{feff}\u{feff}{lf}")]
            .into_iter()
            .map(String::into_bytes)
            .collect()
    };
    let all: Vec<Vec<u8>> = bases.iter().flat_map(|b| variants(b)).collect();
    for a in &all {
        assert_eq!(folders::normalized_len(a), folders::normalized(a).count(), "{:?}", String::from_utf8_lossy(a));
        for b in &all {
            let by_bytes = folders::normalized(a).eq(folders::normalized(b));
            assert_eq!(folders::same_content(a, b), by_bytes, "{:?} vs {:?}", String::from_utf8_lossy(a), String::from_utf8_lossy(b));
            if by_bytes {
                assert_eq!(folders::normalized_len(a), folders::normalized_len(b));
            }
        }
    }
}
