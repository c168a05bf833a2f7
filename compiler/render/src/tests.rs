//! Tests of both pictures on small handmade scenes, and (ignored) one sample picture per
//! road shape written to `$CARGO_TARGET_DIR/render-samples/` to look at.

use crate::view::View;
use crate::{ActorInfo, Event, Frame, GifOptions, Kind, Light, Scene, anim, gif, palette, png, svg};
use tad_road::geom::Vec2;
use tad_road::road::{Junction, LANE_WIDTH, Station, Turn};
use tad_road::{Arm, Road, Shape};

fn road(shape: Shape, crosswalks: bool) -> Road {
    let junction = match shape {
        Shape::Junction { arms, roundabout } => Some(Junction {
            arms: if arms == 3 { vec![Arm::Ego, Arm::Left, Arm::Right] } else { Arm::ALL.to_vec() },
            roundabout,
            half: 8.0,
            signalised: !roundabout,
            stop_signs: false,
        }),
        _ => None,
    };
    Road {
        shape,
        lanes: 1,
        opposite: 1,
        cross_lanes: 1,
        lane_width: LANE_WIDTH,
        sidewalks: true,
        crosswalks,
        signal: None,
        approach: if junction.is_some() { 20.0 } else { 0.0 },
        junction,
    }
}

fn actor(label: &str, kind: Kind, length: f64, width: f64) -> ActorInfo {
    ActorInfo { label: label.to_string(), kind, length, width }
}

/// The ego drives 40 steps of 0.1 s at 8 m/s along its lane from the origin; a car waits on
/// the left arm; the light turns from green to red at step 20; a walker crosses.
fn junction_scene(road: &Road) -> Scene<'_> {
    let frames = (0..40)
        .map(|k| {
            let t = k as f64 * 0.1;
            let walker = if k >= 5 {
                Some([road.approach + 4.0, -5.0 + 0.8 * (t - 0.5), std::f64::consts::FRAC_PI_2])
            } else {
                None
            };
            let light = if k < 20 { Light::Green } else { Light::Red };
            Frame {
                poses: vec![
                    Some([8.0 * t, -1.75, 0.0]),
                    Some([road.centre().x - 1.75, 14.0, -std::f64::consts::FRAC_PI_2]),
                    walker,
                ],
                lights: vec![(Arm::Ego, light), (Arm::Left, Light::Red)],
            }
        })
        .collect();
    Scene {
        road,
        title: "red_light <running> & co · seed 3".to_string(),
        actors: vec![
            actor("ego", Kind::Ego, 4.5, 2.0),
            actor("car_1", Kind::Vehicle, 4.5, 1.9),
            actor("walker_1", Kind::Walker, 0.6, 0.6),
        ],
        frames,
        dt: 0.1,
        route: (0..=60).map(|k| [k as f64 * 2.0 - 20.0, -1.75]).collect(),
        events: vec![Event { step: 30, position: [24.0, -1.75], label: "red light".to_string() }],
    }
}

fn svg_view(doc: &roxmltree::Document) -> Vec<(f64, f64)> {
    let ego =
        doc.descendants().find(|n| n.attribute("id") == Some("actor-0-end")).expect("the ego's last pose is drawn");
    ego.attribute("points")
        .unwrap_or("")
        .split(' ')
        .map(|p| {
            let (x, y) = p.split_once(',').expect("x,y");
            (x.parse().expect("x"), y.parse().expect("y"))
        })
        .collect()
}

#[test]
fn the_svg_is_well_formed_and_shows_the_road_and_the_actors() {
    let road = road(Shape::Junction { arms: 4, roundabout: false }, true);
    let scene = junction_scene(&road);
    let text = svg(&scene);
    let doc = roxmltree::Document::parse(&text).expect("well-formed XML");
    let class = |c: &str| doc.descendants().filter(|n| n.attribute("class") == Some(c)).count();
    // the ego at its last pose: a rectangle 4.5 × 2 m centred at (31.2, -1.75), facing +x
    let view = crate::svg::view_of(&scene);
    let corners = svg_view(&doc);
    assert_eq!(corners.len(), 4);
    let cx = corners.iter().map(|c| c.0).sum::<f64>() / 4.0;
    let cy = corners.iter().map(|c| c.1).sum::<f64>() / 4.0;
    let (ex, ey) = view.px(Vec2::new(31.2, -1.75));
    assert!((cx - ex).abs() < 0.2 && (cy - ey).abs() < 0.2, "({cx}, {cy}) is not ({ex}, {ey})");
    let side = |i: usize, j: usize| (corners[i].0 - corners[j].0).hypot(corners[i].1 - corners[j].1) / view.scale;
    assert!((side(0, 3) - 4.5).abs() < 0.05 && (side(0, 1) - 2.0).abs() < 0.05, "{} × {}", side(0, 3), side(0, 1));
    assert!(corners[0].0 > corners[3].0 && corners[1].0 > corners[2].0, "the front is to the right");
    let ego = doc.descendants().find(|n| n.attribute("id") == Some("actor-0")).expect("the ego's group");
    let start = ego.children().find(|n| n.attribute("class") == Some("actor-start")).expect("the ego's first pose");
    assert!(start.attribute("points").is_some_and(|p| p.split(' ').count() == 4));
    // it drove 3.9 s: a tick at each of 1, 2 and 3 s
    let ticks = ego.children().find(|n| n.attribute("class") == Some("ticks")).expect("the ego's ticks");
    assert_eq!(ticks.attribute("d").unwrap_or("").matches('M').count(), 3);
    assert!(class("route") >= 1, "the route is drawn");
    assert!(class("stop-line") == 4, "a stop line on each arm of a four-way junction");
    assert!(class("crosswalk") >= 4 * 4, "crosswalk stripes across each arm");
    assert!(class("trajectory") >= 2, "the ego's and the walker's trajectories");
    assert!(class("event") == 1 && text.contains(">red light, t = 3.0 s</text>"));
    assert!(class("signal") == 2 && class("signal-end") == 1, "the ego's light changed; the left's did not");
    assert!(text.contains("red_light &lt;running&gt; &amp; co"), "the title is escaped");
    assert!(class("scale") == 1 && text.contains(" m</text>"), "a scale bar");
    assert!(class("legend") == 1);
}

#[test]
fn the_view_is_fitted_to_what_moved() {
    let road = road(Shape::Straight, false);
    let mut scene = junction_scene(&road);
    // a parked car far ahead does not widen the view; the ego's 31 m drive does
    scene.actors.push(actor("far", Kind::Vehicle, 4.5, 1.9));
    for f in &mut scene.frames {
        f.poses.push(Some([150.0, 2.0, 0.0]));
    }
    let view = crate::view::focus(&scene);
    assert!(view.min.x <= -2.25 - 5.0 && view.max.x >= 31.2 + 2.25 + 5.0, "{view:?}");
    assert!(view.width() < 80.0, "{view:?}");
    // the road is drawn near the view only, not 200 m each way
    let map = crate::map::draw(&scene, &view);
    let xs = map.items.iter().flat_map(|i| match i {
        crate::map::Item::Area { points, .. } | crate::map::Item::Line { points, .. } => points.clone(),
        crate::map::Item::Disc { centre, .. } => vec![*centre],
    });
    assert!(xs.clone().all(|p| p.x > view.min.x - 20.0 && p.x < view.max.x + 20.0));
    assert!(xs.clone().any(|p| p.x < view.min.x) && xs.clone().any(|p| p.x > view.max.x), "the road leaves the view");
}

#[test]
fn crosswalks_only_when_the_road_has_them() {
    let road = road(Shape::Junction { arms: 4, roundabout: false }, false);
    let text = svg(&junction_scene(&road));
    assert!(!text.contains("class=\"crosswalk\""));
    assert!(text.contains("class=\"stop-line\""));
    let straight = self::road(Shape::Straight, false);
    let text = svg(&junction_scene(&straight));
    assert!(!text.contains("class=\"stop-line\""), "no junction, no stop line");
}

#[test]
fn a_straight_road_has_a_crosswalk_where_a_walker_crosses() {
    let road = road(Shape::Straight, true);
    let mut scene = junction_scene(&road);
    scene.actors.truncate(1);
    scene.actors.push(actor("walker", Kind::Walker, 0.6, 0.6));
    for (k, f) in scene.frames.iter_mut().enumerate() {
        f.poses = vec![f.poses[0], Some([30.0, -6.0 + 0.2 * k as f64, std::f64::consts::FRAC_PI_2])];
    }
    let text = svg(&scene);
    let doc = roxmltree::Document::parse(&text).expect("well-formed XML");
    let stripes: Vec<_> = doc.descendants().filter(|n| n.attribute("class") == Some("crosswalk")).collect();
    assert_eq!(stripes.len(), 7, "7 m of road, a stripe each metre");
    // the stripes are at x = 30 m: as far right of the ego's start as the walker
    let walker = doc.descendants().find(|n| n.attribute("id") == Some("actor-1-end")).expect("walker");
    let x_of = |n: &roxmltree::Node| {
        let v: Vec<f64> =
            n.attribute("points").unwrap_or("").split([' ', ',']).filter_map(|v| v.parse().ok()).collect();
        v.iter().step_by(2).sum::<f64>() / (v.len() / 2) as f64
    };
    assert!((x_of(&stripes[0]) - x_of(&walker)).abs() < 3.0);
}

#[test]
fn the_same_scene_gives_the_same_bytes() {
    let road = road(Shape::Junction { arms: 3, roundabout: false }, true);
    let scene = junction_scene(&road);
    assert_eq!(svg(&scene), svg(&scene));
    let options = GifOptions { width: 160, height: 120, every: 4, fps: 10 };
    assert_eq!(gif(&scene, options), gif(&scene, options));
}

#[test]
fn the_gif_decodes_with_one_frame_per_stride_and_the_ego_where_it_is() {
    let road = road(Shape::Junction { arms: 4, roundabout: false }, true);
    let scene = junction_scene(&road);
    let options = GifOptions { width: 720, height: 400, every: 4, fps: 10 };
    let bytes = gif(&scene, options);
    let mut decoder = {
        let mut o = ::gif::DecodeOptions::new();
        o.set_color_output(::gif::ColorOutput::RGBA);
        o.read_info(bytes.as_slice()).expect("a GIF")
    };
    assert_eq!((decoder.width(), decoder.height()), (720, 400));
    let first = decoder.read_next_frame().expect("decodes").expect("a first frame").clone();
    assert_eq!((first.width, first.height), (720, 400), "the first frame is whole");
    let mut count = 1;
    while decoder.read_next_frame().expect("decodes").is_some() {
        count += 1;
    }
    assert_eq!(count, 11, "steps 0, 4, …, 36, and the last, 39");
    // the ego's centre at step 0, (0, -1.75), in the ego's colour
    let view: View = anim::view_of(&scene, options);
    let (x, y) = view.px(Vec2::new(0.0, -1.75));
    let i = (y.round() as usize * 720 + x.round() as usize) * 4;
    let ego = palette::kind(Kind::Ego).fill;
    assert_eq!(&first.buffer[i..i + 3], &[ego.0, ego.1, ego.2]);
    // and the left arm's car in the vehicles' colour
    let (x, y) = view.px(Vec2::new(road.centre().x - 1.75, 14.0));
    let i = (y.round() as usize * 720 + x.round() as usize) * 4;
    let car = palette::kind(Kind::Vehicle).fill;
    assert_eq!(&first.buffer[i..i + 3], &[car.0, car.1, car.2]);
}

/// The PNG is the GIF's last frame, pixel for pixel.
#[test]
fn the_png_is_the_last_frame() {
    let road = road(Shape::Junction { arms: 4, roundabout: false }, true);
    let scene = junction_scene(&road);
    let options = GifOptions { width: 720, height: 300, every: 4, fps: 10 };
    let png = tiny_skia::Pixmap::decode_png(&png(&scene, options)).expect("a PNG");
    let last = anim::frames(&scene, options).pop().expect("frames");
    assert_eq!((png.width(), png.height()), (720, 300));
    assert_eq!(png.data(), last.data());
}

#[test]
fn a_long_episode_stays_small() {
    let road = road(Shape::Junction { arms: 4, roundabout: false }, true);
    let mut scene = junction_scene(&road);
    scene.frames = (0..300)
        .map(|k| {
            let t = k as f64 * 0.05;
            Frame {
                poses: vec![
                    Some([6.0 * t, -1.75, 0.0]),
                    Some([road.centre().x - 1.75, 40.0 - 4.0 * t, -std::f64::consts::FRAC_PI_2]),
                    Some([road.approach + 4.0, -5.0 + 0.7 * t, std::f64::consts::FRAC_PI_2]),
                ],
                lights: vec![(Arm::Ego, if k < 150 { Light::Green } else { Light::Red })],
            }
        })
        .collect();
    scene.dt = 0.05;
    let bytes = gif(&scene, GifOptions::default());
    assert!(bytes.len() < 2_000_000, "{} bytes", bytes.len());
    assert!(bytes.len() > 10_000, "the frames hold pictures: {} bytes", bytes.len());
}

#[test]
fn bad_input_still_gives_pictures() {
    let road = road(Shape::Junction { arms: 4, roundabout: true }, true);
    let empty = Scene {
        road: &road,
        title: String::new(),
        actors: vec![],
        frames: vec![],
        dt: f64::NAN,
        route: vec![],
        events: vec![],
    };
    roxmltree::Document::parse(&svg(&empty)).expect("well-formed");
    let bytes = gif(&empty, GifOptions { width: 0, height: 0, every: 0, fps: 0 });
    let decoder = ::gif::DecodeOptions::new().read_info(bytes.as_slice()).expect("a GIF");
    assert_eq!(decoder.width() as u32, palette::GIF_MIN_WIDTH, "never narrower than that");
    assert!(decoder.height() as u32 > 2 * palette::GIF_BAND_PX);
    let odd = Scene {
        road: &road,
        title: "\u{0}\u{7}<>".to_string(),
        actors: vec![actor("x", Kind::Vehicle, f64::NAN, -1.0), actor("y", Kind::Ego, 1e9, 2.0)],
        frames: vec![
            Frame { poses: vec![Some([f64::NAN, 0.0, 0.0])], lights: vec![(Arm::Right, Light::Off)] },
            Frame {
                poses: vec![Some([1.0, 2.0, f64::INFINITY]), Some([1e7, -1e7, 0.0]), Some([0.0, 0.0, 0.0])],
                lights: vec![],
            },
        ],
        dt: -1.0,
        route: vec![[f64::NAN, 1.0], [0.0, 0.0]],
        events: vec![Event { step: 99, position: [f64::INFINITY, 0.0], label: "\u{1}".to_string() }],
    };
    let text = svg(&odd);
    roxmltree::Document::parse(&text).expect("well-formed");
    assert!(!text.contains("NaN") && !text.contains("inf"));
    let bytes = gif(&odd, GifOptions { width: 64, height: 64, every: 1, fps: 1000 });
    assert!(::gif::DecodeOptions::new().read_info(bytes.as_slice()).is_ok());
}

/// A vehicle following the layout's path for `lane` and `turn` from a station, at `speed`.
fn drive(
    road: &Road,
    station: Station,
    lane: i64,
    turn: Turn,
    speed: f64,
    steps: usize,
    dt: f64,
) -> Vec<Option<[f64; 3]>> {
    let (path, start) = road.vehicle_path(station, lane, turn);
    (0..steps)
        .map(|k| {
            let p = path.pose(start + speed * k as f64 * dt);
            Some([p.position.x, p.position.y, p.yaw])
        })
        .collect()
}

/// One sample picture per road shape, to look at: `cargo test -p tad-render -- --ignored`.
#[test]
#[ignore]
fn samples() {
    let dir = std::path::PathBuf::from(std::env::var("CARGO_TARGET_DIR").unwrap_or_else(|_| "target".to_string()))
        .join("render-samples");
    std::fs::create_dir_all(&dir).expect("a directory for the samples");
    let (steps, dt) = (160, 0.05);
    let shapes = [
        ("straight", Shape::Straight),
        ("curve", Shape::Curve { left: true }),
        ("junction4", Shape::Junction { arms: 4, roundabout: false }),
        ("junction3", Shape::Junction { arms: 3, roundabout: false }),
        ("roundabout", Shape::Junction { arms: 4, roundabout: true }),
    ];
    for (name, shape) in shapes {
        let mut road = road(shape, true);
        if name == "straight" {
            road.lanes = 2;
        }
        if name == "junction4" {
            // two lanes each way, and the box as wide as the layout makes it
            (road.lanes, road.opposite, road.cross_lanes) = (2, 2, 2);
            if let Some(j) = road.junction.as_mut() {
                j.half = 2.0 * LANE_WIDTH + 4.5;
            }
        }
        let ego_turn = if name == "junction3" { Turn::Left } else { Turn::Straight };
        let ego = drive(&road, Station { arm: Arm::Ego, along: 0.0 }, 1, ego_turn, 8.0, steps, dt);
        let (other, other_kind) = match shape {
            Shape::Junction { .. } => (
                drive(&road, Station { arm: Arm::Left, along: 25.0 }, 1, Turn::Straight, 7.0, steps, dt),
                Kind::Vehicle,
            ),
            _ => (
                drive(&road, Station { arm: Arm::Ego, along: 30.0 }, -1, Turn::Straight, 6.0, steps, dt),
                Kind::Vehicle,
            ),
        };
        // a walker crosses the ego's road (at a junction, on its crosswalk), a car is parked
        // on the far side facing the oncoming traffic, a dog shows up late on the sidewalk
        let cross = if road.junction.is_some() { road.approach + tad_road::road::CROSSWALK } else { 45.0 };
        let right = -(road.lanes as f64) * road.lane_width - 1.5;
        let walker: Vec<Option<[f64; 3]>> = (0..steps)
            .map(|k| {
                let p = road.ego_road(cross, right + 1.3 * k as f64 * dt);
                Some([p.position.x, p.position.y, p.yaw + std::f64::consts::FRAC_PI_2])
            })
            .collect();
        let at = |along: f64, lateral: f64, turn: f64| {
            let p = road.ego_road(along, lateral);
            Some([p.position.x, p.position.y, p.yaw + turn])
        };
        let parked = at(
            if road.junction.is_some() { 6.0 } else { 60.0 },
            road.opposite as f64 * road.lane_width - 1.1,
            std::f64::consts::PI,
        );
        let dog = at(12.0, road.opposite as f64 * road.lane_width + 1.0, 0.3);
        let frames = (0..steps)
            .map(|k| Frame {
                poses: vec![ego[k], other[k], walker[k], parked, if k > 60 { dog } else { None }],
                lights: if road.junction.as_ref().is_some_and(|j| j.signalised) {
                    vec![
                        (Arm::Ego, if k < 100 { Light::Green } else { Light::Yellow }),
                        (Arm::Left, Light::Red),
                        (Arm::Right, Light::Red),
                        (Arm::Opposite, Light::Green),
                    ]
                } else {
                    vec![]
                },
            })
            .collect();
        let (path, start) = road.vehicle_path(Station { arm: Arm::Ego, along: 0.0 }, 1, ego_turn);
        let scene = Scene {
            road: &road,
            title: format!("sample {name} · seed 1 · ego idm"),
            actors: vec![
                actor("ego", Kind::Ego, 4.6, 2.0),
                actor("adversary", other_kind, 4.5, 1.9),
                actor("walker", Kind::Walker, 0.6, 0.6),
                actor("parked", Kind::Vehicle, 4.5, 1.9),
                actor("dog", Kind::Animal, 0.9, 0.4),
            ],
            frames,
            dt,
            route: path
                .points()
                .iter()
                .filter(|p| p.distance(path.pose(start).position) < 150.0)
                .map(|p| [p.x, p.y])
                .collect(),
            events: vec![Event {
                step: 120,
                position: ego[120].map_or([0.0, 0.0], |p| [p[0], p[1]]),
                label: "lane invasion".to_string(),
            }],
        };
        std::fs::write(dir.join(format!("{name}.svg")), svg(&scene)).expect("write the SVG");
        let options = GifOptions::default();
        let bytes = gif(&scene, options);
        println!("{name}: GIF {} bytes", bytes.len());
        std::fs::write(dir.join(format!("{name}.gif")), bytes).expect("write the GIF");
        let frames = anim::frames(&scene, options);
        for (which, frame) in [("first", frames.first()), ("last", frames.last())] {
            if let Some(f) = frame {
                f.save_png(dir.join(format!("{name}-{which}.png"))).expect("write a frame");
            }
        }
    }
}

/// A crowded straight street: the ego drives 60 m to an event at the view's right edge,
/// a row of five parked cars (one group) beside its lane, twelve walkers crossing in a
/// block, and an oncoming car that starts 150 m away.
fn crowded(road: &Road) -> Scene<'_> {
    let mut actors = vec![actor("ego", Kind::Ego, 4.5, 2.0)];
    actors.extend((0..5).map(|k| actor(&format!("parked[{k}]"), Kind::Vehicle, 4.5, 1.9)));
    actors.extend((0..12).map(|k| actor(&format!("crowd[{k}]"), Kind::Walker, 0.6, 0.6)));
    actors.push(actor("oncoming[0]", Kind::Vehicle, 4.5, 1.9));
    let frames = (0..60)
        .map(|f| {
            let t = f as f64 * 0.1;
            let mut poses = vec![Some([10.0 * t, -1.75, 0.0])];
            poses.extend((0..5).map(|k| Some([8.0 + 6.0 * k as f64, -5.4, 0.0])));
            poses.extend((0..12).map(|k| {
                Some([40.0 + (k % 4) as f64 * 0.9, -8.0 + (k / 4) as f64 * 0.8 + 1.2 * t, std::f64::consts::FRAC_PI_2])
            }));
            poses.push(Some([150.0 - 12.0 * t, 1.75, std::f64::consts::PI]));
            Frame { poses, lights: vec![] }
        })
        .collect();
    Scene {
        road,
        title: "crowded".to_string(),
        actors,
        frames,
        dt: 0.1,
        route: vec![],
        events: vec![Event { step: 59, position: [61.0, -1.75], label: "collision with crowd[3]".to_string() }],
    }
}

/// Every label's box (`data-box`) and the map's rectangle.
fn label_boxes(text: &str) -> (Vec<(String, [f64; 4])>, [f64; 4]) {
    let doc = roxmltree::Document::parse(text).expect("well-formed XML");
    let clip = doc.descendants().find(|n| n.attribute("id") == Some("map-clip")).expect("the map's clip");
    let r = clip.first_element_child().expect("its rectangle");
    let num = |a: &str| r.attribute(a).and_then(|v| v.parse::<f64>().ok()).expect("a number");
    let map = [num("x"), num("y"), num("width"), num("height")];
    let boxes = doc
        .descendants()
        .filter_map(|n| {
            let v: Vec<f64> = n.attribute("data-box")?.split(' ').filter_map(|v| v.parse().ok()).collect();
            Some((n.text().unwrap_or("").to_string(), [v[0], v[1], v[2], v[3]]))
        })
        .collect();
    (boxes, map)
}

#[test]
fn labels_neither_overlap_nor_leave_the_map() {
    let road = road(Shape::Straight, true);
    let scene = crowded(&road);
    let text = svg(&scene);
    let (boxes, map) = label_boxes(&text);
    let names: Vec<&str> = boxes.iter().map(|(t, _)| t.as_str()).collect();
    for wanted in ["ego", "parked[0–4]", "collision with crowd[3], t = 5.9 s"] {
        assert!(names.contains(&wanted), "{wanted} is not among {names:?}");
    }
    assert!(names.iter().any(|n| n.starts_with("crowd[")), "the crowd is named: {names:?}");
    assert!(names.iter().filter(|n| n.ends_with(" s") && n.len() <= 5).count() >= 3, "time marks: {names:?}");
    for (i, (a, ra)) in boxes.iter().enumerate() {
        let inside = ra[0] >= map[0] && ra[1] >= map[1] && ra[0] + ra[2] <= map[0] + map[2];
        assert!(inside && ra[1] + ra[3] <= map[1] + map[3], "{a} at {ra:?} leaves the map {map:?}");
        for (b, rb) in &boxes[i + 1..] {
            let apart =
                ra[0] + ra[2] <= rb[0] || rb[0] + rb[2] <= ra[0] || ra[1] + ra[3] <= rb[1] || rb[1] + rb[3] <= ra[1];
            assert!(apart, "{a} {ra:?} overlaps {b} {rb:?}");
        }
    }
    // labels come after (over) the signals and the event's ring, which is hollow
    let labels_at = text.find("<g class=\"labels\">").expect("labels");
    assert!(text.find("<g class=\"events\">").is_some_and(|e| e < labels_at));
    assert!(text.contains("class=\"event\" ") && text.contains("fill=\"none\" stroke=\"#ffd700\""));
}

#[test]
fn placement_keeps_apart_what_would_stack() {
    use crate::label::{Rect, Request, place};
    let frame = Rect { x: 0.0, y: 0.0, w: 300.0, h: 120.0 };
    // ten labels on one spot near the right edge
    let requests: Vec<Request> = (0..10)
        .map(|k| Request {
            text: format!("actor_{k}"),
            font: 11.0,
            anchor: Rect::around((290.0, 60.0), 3.0),
            optional: false,
            along: None,
        })
        .collect();
    let placed = place(&requests, &[], frame);
    let boxes: Vec<Rect> = placed.iter().flatten().map(|p| p.rect).collect();
    assert!(boxes.len() >= 6, "most find a place: {boxes:?}");
    for (i, a) in boxes.iter().enumerate() {
        assert!(a.inside(&frame), "{a:?}");
        assert!(boxes[i + 1..].iter().all(|b| a.overlap(b) == 0.0), "{a:?} overlaps");
    }
    assert!(placed.iter().flatten().any(|p| p.leader), "the far ones are led back");
    // an optional label never covers an obstacle, and is dropped rather than moved away
    let wall = Rect { x: 0.0, y: 0.0, w: 300.0, h: 120.0 };
    let optional = Request {
        text: "4 s".into(),
        font: 9.0,
        anchor: Rect::around((150.0, 60.0), 2.0),
        optional: true,
        along: None,
    };
    assert_eq!(place(&[optional], &[wall], frame), vec![None]);
}

#[test]
fn the_view_holds_where_things_happen_and_not_more() {
    let road = road(Shape::Straight, true);
    let scene = crowded(&road);
    let view = crate::svg::view_of(&scene);
    let inside = |x: f64, y: f64| view.bounds.contains(Vec2::new(x, y));
    for f in &scene.frames {
        let [x, y, _] = f.poses[0].expect("the ego");
        assert!(inside(x, y), "the ego at ({x}, {y}) is outside {:?}", view.bounds);
        for p in f.poses[1..18].iter().flatten() {
            assert!(inside(p[0], p[1]), "({}, {}) is outside {:?}", p[0], p[1], view.bounds);
        }
    }
    assert!(inside(61.0, -1.75), "the event");
    // the oncoming car's approach from 150 m does not stretch the view
    assert!(view.bounds.max.x < 90.0, "{:?}", view.bounds);
    // and the map is wide, not two thirds empty: the road's width fills a third of it
    assert!(view.bounds.height() < 30.0, "{:?}", view.bounds);
}

#[test]
fn the_gif_is_wide_titled_with_a_legend_and_a_scale_and_the_ego_stands_out() {
    let road = road(Shape::Straight, true);
    let scene = crowded(&road);
    let options = GifOptions::default();
    let layout = anim::layout(&scene, options);
    assert!(layout.width >= 720, "{}", layout.width);
    let frames = anim::frames(&scene, GifOptions { every: 30, ..options });
    let first = &frames[0];
    let at = |x: u32, y: u32| {
        let p = first.pixel(x, y).expect("a pixel");
        palette::Colour(p.red(), p.green(), p.blue())
    };
    let band = layout.band;
    let ink_in = |x0: u32, x1: u32, y0: u32, y1: u32| {
        (x0..x1).flat_map(|x| (y0..y1).map(move |y| (x, y))).filter(|&(x, y)| at(x, y) == palette::INK).count()
    };
    assert!(ink_in(0, 200, 0, band) > 50, "a title in the top band");
    let h = layout.height;
    assert!(ink_in(layout.width - 150, layout.width, h - band, h) > 40, "a scale bar and its metres");
    let swatches = (0..400).flat_map(|x| (h - band..h).map(move |y| (x, y)));
    for k in [Kind::Ego, Kind::Vehicle, Kind::Walker] {
        assert!(swatches.clone().any(|(x, y)| at(x, y) == palette::kind(k).fill), "{k:?} in the legend");
    }
    // the ego: at least 12 px long, in its colour, with a white halo
    let (x, y) = layout.view.px(Vec2::new(0.0, -1.75));
    let (x, y) = (x.round() as u32, y.round() as u32);
    let ego = palette::kind(Kind::Ego).fill;
    let run = (x.saturating_sub(20)..x + 20)
        .filter(|&i| at(i, y) == ego || at(i, y) == palette::kind(Kind::Ego).dark)
        .count();
    assert!(run >= 12, "the ego is {run} px long");
    assert!((0..40).any(|d| at(x, y.saturating_sub(d)) == palette::PAPER), "a halo above the ego");
}
