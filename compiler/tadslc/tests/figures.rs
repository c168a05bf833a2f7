//! The figures in `docs/figures/`, made by the real pipeline: `run.svg`, `run.png` and
//! `run.gif` (`tadslc run --render` of `examples/safety/straight_obstacle.tad`, the naive
//! ego hitting the pedestrian who steps out from behind the van), `eval.svg` (`eval
//! --plot`'s chart, `tad_eval::results::plot`, of the `run --out` results of the safety and
//! the region examples as two generators) and `compare.svg` (`tadslc compare --plot`,
//! attribute-share embeddings of the two folders). Each must equal its checked-in file, and
//! each is checked for what makes it readable (labels apart and inside the map, a GIF at
//! least 720 px wide, error bars with the intervals' values, points inside the frame).
//!
//! `TAD_BLESS=1 cargo test -p tadslc --test figures` rewrites them; never when `CI` is set.

mod common;

use common::{code, repo, scratch, stderr, tadslc};
use std::path::{Path, PathBuf};

fn bless() -> bool {
    std::env::var_os("TAD_BLESS").is_some() && std::env::var_os("CI").is_none()
}

/// `made` equals `docs/figures/NAME`, or (blessing) becomes it; a message when it does not.
fn golden(name: &str, made: &Path) -> Option<String> {
    let path = repo().join("docs/figures").join(name);
    let bytes = std::fs::read(made).unwrap_or_else(|e| panic!("{} was not written: {e}", made.display()));
    if bless() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &bytes).unwrap();
        return None;
    }
    match std::fs::read(&path) {
        Ok(expected) if expected == bytes => None,
        Ok(_) => Some(format!("{} differs (TAD_BLESS=1 to accept)", path.display())),
        Err(_) => Some(format!("{} is missing (TAD_BLESS=1 to create it)", path.display())),
    }
}

fn run(args: &[&str]) {
    let out = tadslc(args, "");
    assert_eq!(code(&out), 0, "tadslc {}: {}", args.join(" "), stderr(&out));
}

fn path(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

/// A rectangle from `data-box="x y w h"`.
fn rect(node: &roxmltree::Node, attribute: &str) -> [f64; 4] {
    let v: Vec<f64> = node.attribute(attribute).unwrap_or("").split(' ').map(|v| v.parse().unwrap()).collect();
    [v[0], v[1], v[2], v[3]]
}

fn overlap(a: [f64; 4], b: [f64; 4]) -> bool {
    a[0] < b[0] + b[2] && b[0] < a[0] + a[2] && a[1] < b[1] + b[3] && b[1] < a[1] + a[3]
}

/// The run figure: labels apart and inside the map, the event ringed, time marks, the
/// legend and the scale bar.
fn check_run_svg(text: &str) {
    let doc = roxmltree::Document::parse(text).expect("well-formed");
    let clip = doc.descendants().find(|n| n.attribute("id") == Some("map-clip")).unwrap();
    let map = clip.first_element_child().unwrap();
    let num = |a: &str| map.attribute(a).unwrap().parse::<f64>().unwrap();
    let frame = [num("x"), num("y"), num("width"), num("height")];
    let labels: Vec<roxmltree::Node> = doc.descendants().filter(|n| n.attribute("data-box").is_some()).collect();
    let boxes: Vec<[f64; 4]> = labels.iter().map(|n| rect(n, "data-box")).collect();
    assert!(labels.iter().any(|n| n.attribute("class") == Some("event-label")), "the collision is named");
    assert!(labels.iter().any(|n| n.text() == Some("ego")), "the ego is named");
    assert!(labels.iter().any(|n| n.text() == Some("parked_sedans[0–4]")), "the parked row shares one label");
    assert!(labels.iter().filter(|n| n.attribute("class") == Some("time-label")).count() >= 3, "time marks");
    for (i, a) in boxes.iter().enumerate() {
        let inside = a[0] >= frame[0] && a[1] >= frame[1] && a[0] + a[2] <= frame[0] + frame[2];
        assert!(inside && a[1] + a[3] <= frame[1] + frame[3], "{:?} leaves the map {frame:?}", labels[i].text());
        for (j, b) in boxes.iter().enumerate().skip(i + 1) {
            assert!(!overlap(*a, *b), "{:?} overlaps {:?}", labels[i].text(), labels[j].text());
        }
    }
    assert!(doc.descendants().any(|n| n.attribute("class") == Some("event") && n.attribute("fill") == Some("none")));
    assert!(doc.descendants().any(|n| n.attribute("class") == Some("scale")), "a scale bar");
    assert!(doc.descendants().any(|n| n.attribute("class") == Some("legend")), "a legend");
}

#[test]
fn the_figures_in_docs_are_made_by_the_pipeline() {
    let out = scratch("figures");
    let mut failures = Vec::new();
    let example = "examples/safety/straight_obstacle.tad";
    for ext in ["svg", "png", "gif"] {
        let file = out.join(format!("run.{ext}"));
        run(&["run", example, "--ego", "naive", "--seeds", "0", "--render", &path(&file)]);
        failures.extend(golden(&format!("run.{ext}"), &file));
    }
    check_run_svg(&std::fs::read_to_string(out.join("run.svg")).unwrap());
    let gif = std::fs::read(out.join("run.gif")).unwrap();
    assert!(gif.starts_with(b"GIF89a") && gif.len() > 10, "a GIF");
    let width = u16::from_le_bytes([gif[6], gif[7]]);
    assert!(width >= 720, "the GIF is {width} px wide");

    // eval --plot: the safety and the region examples as two generators, three egos
    let mut all = Vec::new();
    for (name, folder) in [("safety examples", "examples/safety"), ("region examples", "examples/regions")] {
        let dir = out.join(name.replace(' ', "-"));
        run(&["run", folder, "--ego", "idm,naive,ppo", "--seeds", "0..3", "--out", &path(&dir)]);
        let mut results = tad_eval::results::Results::read(&dir.join("results.json")).unwrap();
        for row in &mut results.rows {
            row.generator = name.to_string();
        }
        results.scenarios = results.scenarios.values().map(|n| (format!("all/{name}"), *n)).collect();
        all.push(results);
    }
    all[0].setup.generators = vec!["safety examples".into(), "region examples".into()];
    let eval = tad_eval::results::plot(&all);
    std::fs::write(out.join("eval.svg"), &eval).unwrap();
    failures.extend(golden("eval.svg", &out.join("eval.svg")));
    let doc = roxmltree::Document::parse(&eval).expect("well-formed");
    let bars = doc.descendants().filter(|n| n.attribute("class") == Some("bar")).count();
    let errors = doc.descendants().filter(|n| n.attribute("class") == Some("error-bar")).count();
    assert_eq!((bars, errors), (6, 6), "two generators × three egos, each with its interval");
    for bar in doc.descendants().filter(|n| n.attribute("class") == Some("bar")) {
        let title = bar.first_element_child().and_then(|t| t.text()).unwrap_or("");
        let value: f64 = title.rsplit(": ").next().unwrap().parse().unwrap();
        let whisker = bar.next_sibling_element().filter(|n| n.attribute("class") == Some("error-bar")).unwrap();
        let (low, high): (f64, f64) = (
            whisker.attribute("data-low").unwrap().parse().unwrap(),
            whisker.attribute("data-high").unwrap().parse().unwrap(),
        );
        assert!(low <= value + 1e-3 && value <= high + 1e-3, "{title}: [{low}, {high}]");
    }
    assert!(doc.descendants().any(|n| n.attribute("class") == Some("axis-title")));

    // compare --plot
    let compare = out.join("compare.svg");
    let args = ["compare", "examples/safety", "examples/regions", "--embedding", "features", "--plot", &path(&compare)];
    run(&args);
    failures.extend(golden("compare.svg", &compare));
    let text = std::fs::read_to_string(&compare).unwrap();
    let doc = roxmltree::Document::parse(&text).expect("well-formed");
    let area = doc.descendants().find(|n| n.attribute("class") == Some("plot-area")).unwrap();
    let num = |a: &str| area.attribute(a).unwrap().parse::<f64>().unwrap();
    let (x, y, w, h) = (num("x"), num("y"), num("width"), num("height"));
    let points: Vec<(f64, f64)> = doc
        .descendants()
        .filter(|n| n.has_tag_name("circle"))
        .map(|n| (n.attribute("cx").unwrap().parse().unwrap(), n.attribute("cy").unwrap().parse().unwrap()))
        .collect();
    assert_eq!(points.len(), 8 + 6, "one point per scenario");
    assert!(points.iter().all(|&(px, py)| px - 4.0 >= x && px + 4.0 <= x + w && py - 4.0 >= y && py + 4.0 <= y + h));
    assert!(text.contains("PC1") && text.contains("PC2"), "axis titles");

    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `--render DIR` draws every episode, one SVG per scenario, ego and seed.
#[test]
fn render_into_a_directory_draws_every_episode() {
    let out = scratch("figures-dir");
    let dir: PathBuf = out.join("pictures");
    run(&[
        "run",
        "examples/safety/straight_obstacle.tad",
        "examples/safety/right_turn.tad",
        "--ego",
        "idm,naive",
        "--seeds",
        "0..2",
        "--render",
        &path(&dir),
    ]);
    let mut names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(names.len(), 2 * 2 * 2, "{names:?}");
    assert!(names.contains(&"right_turn.naive.seed1.svg".to_string()), "{names:?}");
    for name in &names {
        let text = std::fs::read_to_string(dir.join(name)).unwrap();
        roxmltree::Document::parse(&text).expect("well-formed");
    }
    // another extension is still refused, with status 2
    let refused = tadslc(&["run", "examples/safety/right_turn.tad", "--render", &path(&out.join("x.jpg"))], "");
    assert_eq!(code(&refused), 2);
    assert!(stderr(&refused).contains(".svg, .png or .gif"));
}
