//! Hand-computed scores: every expected value is worked out in a comment.

use super::*;
use std::f64::consts::PI;

const EPS: f64 = 1e-12;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= EPS * (1.0 + b.abs())
}

#[track_caller]
fn assert_close(actual: f64, expected: f64) {
    assert!(close(actual, expected), "{actual} != {expected}");
}

/// Four steps, 0.1 s apart, ending in a collision.
fn crash() -> Vec<StepRecord> {
    // motion and route in full, as `one_episode_by_hand` adds them up; the event counts below
    let mut r = vec![
        StepRecord {
            time: 0.0,
            acceleration: [3.0, 4.0, 0.0],
            yaw_deg: 10.0,
            driven_distance: 0.0,
            off_road: false,
            distance_to_route: 1.0,
            route_complete: 0.0,
            ..StepRecord::default()
        },
        StepRecord {
            time: 0.1,
            acceleration: [0.0, 0.0, 0.0],
            yaw_deg: 20.0,
            driven_distance: 1.0,
            off_road: true,
            distance_to_route: 2.0,
            route_complete: 10.0,
            ..StepRecord::default()
        },
        StepRecord {
            time: 0.2,
            acceleration: [1.0, 0.0, 0.0],
            yaw_deg: 15.0,
            driven_distance: 3.0,
            off_road: false,
            distance_to_route: 0.0,
            route_complete: 20.0,
            ..StepRecord::default()
        },
        StepRecord {
            time: 0.3,
            acceleration: [0.0, 2.0, 0.0],
            yaw_deg: 15.0,
            driven_distance: 6.0,
            off_road: false,
            distance_to_route: 1.0,
            route_complete: 30.0,
            ..StepRecord::default()
        },
    ];
    r[1].lane_invasion = 1;
    r[2].lane_invasion = 1;
    r[2].run_red_light = 1;
    r[3].lane_invasion = 2;
    r[3].run_red_light = 1;
    r[3].run_stop = 1;
    r[3].collision = true;
    r
}

#[test]
fn one_episode_by_hand() {
    // CR 1 (last record collided); RR 1; SS 1; LI 2 (last counts).
    // OR: off-road [F, T, F, F] dilated one step forward [F, T, T, F]: steps 1 and 2
    //     count their driven distance, (1 − 0) + (3 − 1) = 3 m.
    // RF: mean distance (1 + 2 + 0 + 1) / 4 = 1 m, max(1 − 1/5, 0) = 0.8.
    // Comp 30 / 100 = 0.3. TS: not completed: Compat 0, Fixed None.
    // ACC: (‖(3,4,0)‖ + 0 + 1 + 2) / 4 = (5 + 0 + 1 + 2) / 4 = 2 m/s².
    // YV: |20−10| + |15−20| + |15−15| = 15° = π/12 rad over T = 0.3 s: π/3.6 rad/s.
    for mode in [Mode::Compat, Mode::Fixed] {
        let e = score_episode(&crash(), mode).unwrap();
        assert_eq!((e.steps, e.completed), (4, false));
        assert_close(e.duration, 0.3);
        assert_close(e.mean_distance_to_route, 1.0);
        let m = &e.metrics;
        assert_eq!((m.cr, m.rr, m.ss, m.li), (1.0, 1.0, 1.0, 2.0));
        assert_close(m.or, 3.0);
        assert_close(m.rf, 0.8);
        assert_close(m.comp, 0.3);
        assert_close(m.acc, 2.0);
        assert_close(m.yv, PI / 3.6);
    }
    // Normalised: CR 1, RR 1, SS 1, OR 3/50 = 0.06, RF 0.8, Comp 0.3, TS 0/60,
    // ACC 2/8 = 0.25, YV π/10.8, LI 2/20 = 0.1.
    // safety  = 5(1−1) + (3 − 1 − 1 − 0.06)         = 0.94
    // task    = 0.5(0.8 + 0.3 + 1 − 0)               = 1.05   (Fixed: 0.5(0.8 + 0.3) = 0.55)
    // comfort = 0.2(3 − 0.25 − π/10.8 − 0.1)
    let comfort = 0.2 * (3.0 - 0.25 - PI / 10.8 - 0.1);
    let compat = aggregate(&[score_episode(&crash(), Mode::Compat).unwrap()], Mode::Compat).unwrap();
    assert_eq!(compat.raw.ts, Some(0.0));
    assert_close(compat.raw.os, (0.94 + 1.05 + comfort) / 10.1);
    assert_close(compat.safety, 0.94 / 8.0);
    assert_close(compat.task, 1.05 / 1.5);
    assert_close(compat.comfort, comfort / 0.6);
    assert_close(compat.normalised.or, 0.06);
    assert_close(compat.normalised.yv, PI / 10.8);
    // Fixed leaves the TS term out of OS (weights 10.1 − 0.5) and of task (1.5 − 0.5).
    let fixed = aggregate(&[score_episode(&crash(), Mode::Fixed).unwrap()], Mode::Fixed).unwrap();
    assert_eq!((fixed.raw.ts, fixed.normalised.ts), (None, None));
    assert_close(fixed.raw.os, (0.94 + 0.55 + comfort) / 9.6);
    assert_close(fixed.task, 0.55);
    assert_close(fixed.safety, compat.safety);
    // An episode scored alone is the aggregate of a set of one.
    assert_eq!(score_episode(&crash(), Mode::Fixed).unwrap().metrics, fixed.raw);
}

#[test]
fn yaw_crossing_180() {
    // 170° → −170° → −160°: Compat sums |−340| + |10| = 350°; Fixed wraps −340° to 20°:
    // 20 + 10 = 30°. T = 0.2 s.
    let r = [
        StepRecord { time: 0.0, yaw_deg: 170.0, ..StepRecord::default() },
        StepRecord { time: 0.1, yaw_deg: -170.0, driven_distance: 1.0, ..StepRecord::default() },
        StepRecord { time: 0.2, yaw_deg: -160.0, driven_distance: 2.0, ..StepRecord::default() },
    ];
    assert_close(score_episode(&r, Mode::Compat).unwrap().metrics.yv, 350.0_f64.to_radians() / 0.2);
    assert_close(score_episode(&r, Mode::Fixed).unwrap().metrics.yv, 30.0_f64.to_radians() / 0.2);
    // −180° to 180° is no turn at all once wrapped.
    let flip = [
        StepRecord { time: 0.0, yaw_deg: -180.0, ..StepRecord::default() },
        StepRecord { time: 0.5, yaw_deg: 180.0, ..StepRecord::default() },
    ];
    assert_close(score_episode(&flip, Mode::Fixed).unwrap().metrics.yv, 0.0);
    assert_close(score_episode(&flip, Mode::Compat).unwrap().metrics.yv, 2.0 * PI / 0.5);
}

#[test]
fn nothing_completes() {
    // Two episodes, neither completes: Compat reports TS 0 (its term scores +0.5);
    // Fixed reports none and drops the term.
    let a = crash();
    let mut b = crash();
    b[3].collision = false;
    for mode in [Mode::Compat, Mode::Fixed] {
        let eps = [score_episode(&a, mode).unwrap(), score_episode(&b, mode).unwrap()];
        let agg = aggregate(&eps, mode).unwrap();
        assert_eq!(agg.completed, 0);
        assert_close(agg.raw.cr, 0.5);
        let expected_ts = if mode == Mode::Compat { Some(0.0) } else { None };
        assert_eq!(agg.raw.ts, expected_ts);
        let s = scores(&agg.normalised);
        assert_close(agg.raw.os, s.os);
    }
    // Serialised, "not applicable" is null.
    let fixed = aggregate(&[score_episode(&a, Mode::Fixed).unwrap()], Mode::Fixed).unwrap();
    let json = serde_json::to_value(&fixed.raw).unwrap();
    assert!(json["TS"].is_null());
}

#[test]
fn time_spent_averages_completed_episodes_only() {
    // Completed in 2 s; the other (5 s, 50 %) does not count: TS = 2, Comp = 0.75.
    let done = [
        StepRecord { time: 1.0, ..StepRecord::default() },
        StepRecord { time: 3.0, driven_distance: 20.0, route_complete: 100.0, ..StepRecord::default() },
    ];
    let half = [
        StepRecord { time: 0.0, ..StepRecord::default() },
        StepRecord { time: 5.0, driven_distance: 10.0, route_complete: 50.0, ..StepRecord::default() },
    ];
    for mode in [Mode::Compat, Mode::Fixed] {
        let eps = [score_episode(&done, mode).unwrap(), score_episode(&half, mode).unwrap()];
        assert_eq!(eps[0].metrics.ts, Some(2.0));
        let agg = aggregate(&eps, mode).unwrap();
        assert_eq!((agg.completed, agg.raw.ts), (1, Some(2.0)));
        assert_close(agg.raw.comp, 0.75);
        assert_close(agg.normalised.ts.unwrap(), 2.0 / 60.0);
    }
}

#[test]
fn route_following_aggregates_the_mean_distance() {
    // Mean distances 0 m and 10 m: RF = max(1 − 5/5, 0) = 0, not the mean of the
    // per-episode stabilities (1 + 0) / 2.
    let near = [StepRecord { time: 0.0, ..StepRecord::default() }];
    let far = [StepRecord { time: 0.0, distance_to_route: 10.0, ..StepRecord::default() }];
    let eps = [score_episode(&near, Mode::Fixed).unwrap(), score_episode(&far, Mode::Fixed).unwrap()];
    assert_eq!((eps[0].metrics.rf, eps[1].metrics.rf), (1.0, 0.0));
    assert_eq!(aggregate(&eps, Mode::Fixed).unwrap().raw.rf, 0.0);
    // 2 m and 4 m: 1 − 3/5 = 0.4.
    let a = [StepRecord { time: 0.0, distance_to_route: 2.0, ..StepRecord::default() }];
    let b = [StepRecord { time: 0.0, distance_to_route: 4.0, ..StepRecord::default() }];
    let eps = [score_episode(&a, Mode::Fixed).unwrap(), score_episode(&b, Mode::Fixed).unwrap()];
    assert_close(aggregate(&eps, Mode::Fixed).unwrap().raw.rf, 0.4);
}

#[test]
fn off_road_dilation_at_the_edges() {
    // Off road at step 0 only: dilated to step 1, which counts 4 m; step 0 never counts.
    // Off road at the last step: counts its own 1 m, nothing after it.
    let r = [
        StepRecord { time: 0.0, off_road: true, ..StepRecord::default() },
        StepRecord { time: 0.1, driven_distance: 4.0, ..StepRecord::default() },
        StepRecord { time: 0.2, driven_distance: 6.0, ..StepRecord::default() },
        StepRecord { time: 0.3, driven_distance: 7.0, off_road: true, ..StepRecord::default() },
    ];
    assert_close(score_episode(&r, Mode::Compat).unwrap().metrics.or, 5.0);
}

#[test]
fn perfect_scores_one() {
    let best = Metrics {
        cr: 0.0,
        rr: 0.0,
        ss: 0.0,
        or: 0.0,
        rf: 1.0,
        comp: 1.0,
        ts: Some(0.0),
        acc: 0.0,
        yv: 0.0,
        li: 0.0,
        os: 0.0,
    };
    let s = scores(&best);
    assert_eq!((s.os, s.safety, s.task, s.comfort), (1.0, 1.0, 1.0, 1.0));
    assert_eq!(scores(&Metrics { ts: None, ..best }).os, 1.0);
    // A one-step episode on the route, complete at once, calm: OS 1 in both modes.
    let r = [StepRecord { time: 0.0, yaw_deg: 90.0, route_complete: 100.0, ..StepRecord::default() }];
    for mode in [Mode::Compat, Mode::Fixed] {
        let e = score_episode(&r, mode).unwrap();
        assert_eq!((e.metrics.os, e.metrics.yv), (1.0, 0.0));
    }
}

#[test]
fn published_rows() {
    // TrafficAlign's table, normalised columns (note §1.5). Learning-to-collide:
    // (5·0.416 + (3 − .326 − .158 − .032) + 0.5(.894 + .731 + 1 − .216)
    //  + 0.2(3 − .211 − .243 − .112)) / 10.1 = 6.2553 / 10.1 = 0.6193 → 0.619 as published.
    let row = |v: [f64; 10]| Metrics {
        cr: v[0],
        rr: v[1],
        ss: v[2],
        or: v[3],
        rf: v[4],
        comp: v[5],
        ts: Some(v[6]),
        acc: v[7],
        yv: v[8],
        li: v[9],
        os: f64::NAN,
    };
    let ltc = row([0.584, 0.326, 0.158, 0.032, 0.894, 0.731, 0.216, 0.211, 0.243, 0.112]);
    assert_close(scores(&ltc).os, 6.2553 / 10.1);
    assert_eq!((scores(&ltc).os * 1000.0).round(), 619.0);
    // ChatScene's row recomputes to 0.486 (published 0.481; the note explains why).
    let chatscene = row([0.825, 0.191, 0.142, 0.035, 0.861, 0.537, 0.213, 0.706, 0.533, 0.228]);
    assert_eq!((scores(&chatscene).os * 1000.0).round(), 486.0);
}

#[test]
fn table_is_consistent() {
    for (i, d) in METRICS.iter().enumerate() {
        assert_eq!(d.metric as usize, i);
        assert!(d.max > 0.0 && d.weight > 0.0);
    }
    assert_close(METRICS.iter().map(|d| d.weight).sum(), 10.1);
    let group = |g: Group| METRICS.iter().filter(|d| d.group == g).map(|d| d.weight).sum::<f64>();
    assert_close(group(Group::Safety), 8.0);
    assert_close(group(Group::Task), 1.5);
    assert_close(group(Group::Comfort), 0.6);
    let higher: Vec<&str> = METRICS.iter().filter(|d| d.higher_is_better).map(|d| d.key).collect();
    assert_eq!(higher, ["RF", "Comp"]);
}

#[test]
fn serialised_keys() {
    let e = score_episode(&crash(), Mode::Compat).unwrap();
    let json = serde_json::to_value(&e.metrics).unwrap();
    let keys: Vec<&String> = json.as_object().unwrap().keys().collect();
    let mut expected: Vec<&str> = METRICS.iter().map(|d| d.key).collect();
    expected.push("OS");
    let mut keys: Vec<&str> = keys.iter().map(|k| k.as_str()).collect();
    keys.sort_unstable();
    expected.sort_unstable();
    assert_eq!(keys, expected);
    let back: Metrics = serde_json::from_value(json).unwrap();
    assert_eq!(back, e.metrics);
    assert_eq!(serde_json::to_value(Mode::Compat).unwrap(), "compat");
}

#[test]
fn names_round_trip() {
    for r in StopReason::ALL {
        assert_eq!(r.as_str().parse::<StopReason>(), Ok(r));
        assert_eq!(serde_json::to_value(r).unwrap(), r.as_str());
    }
    let names: Vec<&str> = StopReason::ALL.iter().map(|r| r.as_str()).collect();
    assert_eq!(
        names,
        [
            "collision",
            "off_road",
            "route_complete",
            "max_steps",
            "max_distance",
            "timeout",
            "program_end",
            "ego_failed"
        ]
    );
    assert!(StopReason::Collision < StopReason::ProgramEnd);
    let err = "crash".parse::<StopReason>().unwrap_err();
    assert!(err.contains("`crash`") && err.contains("program_end"), "{err}");
    assert_eq!("compat".parse::<Mode>(), Ok(Mode::Compat));
    assert!("strict".parse::<Mode>().unwrap_err().contains("`compat` or `fixed`"));
    assert!(Mode::Fixed.off_road_terminates() && !Mode::Compat.off_road_terminates());
    assert_eq!(Mode::default(), Mode::Fixed);
}

#[test]
fn bad_records_are_errors() {
    assert_eq!(score_episode(&[], Mode::Fixed), Err(MetricsError::EmptyEpisode));
    assert_eq!(aggregate(&[], Mode::Fixed), Err(MetricsError::NoEpisodes));
    let mut r = crash();
    r[2].acceleration[1] = f64::NAN;
    assert_eq!(score_episode(&r, Mode::Fixed), Err(MetricsError::NonFinite { step: 2, field: "acceleration" }));
    let mut r = crash();
    r[3].time = 0.05;
    let err = score_episode(&r, Mode::Fixed).unwrap_err();
    assert_eq!(err, MetricsError::TimeBackwards { step: 3 });
    assert_eq!(err.to_string(), "step 3: `time` is earlier than the previous step's");
}

#[test]
fn the_normalisation_footer_names_every_maximum_that_is_not_a_share() {
    let text = normalisation();
    for d in METRICS {
        assert_eq!(text.contains(&format!("{} {}", d.key, d.max)), d.max != 1.0, "{text}");
    }
}
