//! A vehicle's computer built from its configuration file with the onboard crate alone
//! (no simulator): parse, check, build the unit, run JSON lines through it.

use onebeacon::config::stream::StreamConfig;
use onebeacon::io::stream;
use serde_json::Value;
use std::io::Cursor;

const CONFIG: &str = r#"
name = "computer"
frame = "ned"

[[beacon]]
id = 7
x_m = 100.0
y_m = 0.0

[initial]
from = "given"
x_m = 3.0
y_m = 4.0
heading_deg = 0.0
position_sigma_m = 10.0

[[estimators]]
kind = "rosb"

[[estimators]]
kind = "dead-reckoning"

[noise]
range_sigma_m = 0.5
"#;

fn config(text: &str) -> StreamConfig {
    toml::from_str(text).expect("a stream configuration")
}

/// The last output line of a unit of `config` fed a still vehicle's lines 100 m from
/// beacon 7 for 60 s.
fn last_line(config: StreamConfig) -> Value {
    let mut unit = config.unit().unwrap();
    let mut input = String::new();
    for k in 1..=60 {
        let t = f64::from(k);
        input += &format!("{{\"t_s\": {t}, \"kind\": \"odometry\", \"distance_m\": 0, \"heading_change_rad\": 0}}\n");
        input += &format!("{{\"t_s\": {t}, \"kind\": \"heading\", \"heading_rad\": 0}}\n");
        input += &format!("{{\"t_s\": {}, \"kind\": \"range\", \"beacon\": 7, \"range_m\": 100}}\n", t + 0.5);
    }
    let mut out = Vec::new();
    let mut notes = Vec::new();
    stream::run(&mut unit, Cursor::new(input), &mut out, |line, m| notes.push(format!("{line}: {m}"))).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    serde_json::from_str(std::str::from_utf8(&out).unwrap().lines().last().unwrap()).unwrap()
}

/// A calibration state is written where the estimator estimates it and left out where
/// it does not (absent is not zero): the range filter's offset with `estimate_bias`,
/// none of dead reckoning's.
#[test]
fn calibration_not_estimated_is_absent() {
    let calibrated = CONFIG.replacen("kind = \"rosb\"", "kind = \"rosb\"\nestimate_bias = true", 1);
    let last = last_line(config(&calibrated).checked().unwrap());
    assert!(last["estimates"][0]["range_bias_m"].is_f64(), "{last}");
    for key in ["range_scale", "distance_scale", "turn_scale", "usbl_misalignment_rad", "current_north_m_s"] {
        assert!(last["estimates"][0].get(key).is_none(), "{key}: {last}");
    }
    let plain = last_line(config(CONFIG).checked().unwrap());
    assert!(plain["estimates"][0].get("range_bias_m").is_none() && plain["estimates"][1].get("range_bias_m").is_none());
}

/// A still vehicle hearing the beacon 100 m away: the range filter's position ends on
/// the 100 m circle about the beacon (within 10 of the filter's range sigmas, 0.5 m /
/// sqrt(60) each), dead reckoning stays exactly where it started.
#[test]
fn a_configured_unit_estimates_from_its_lines() {
    let c = config(CONFIG).checked().unwrap();
    assert_eq!(c.estimators[0].noise.range_sigma_m, Some(0.5), "[noise] is handed to the estimators");
    let last = last_line(c);
    let estimate = |i: usize| {
        let e = &last["estimates"][i];
        (e["x_m"].as_f64().unwrap(), e["y_m"].as_f64().unwrap())
    };
    let (x, y) = estimate(0);
    let range = (x - 100.0).hypot(y);
    assert!((range - 100.0).abs() < 10.0 * 0.5 / 60f64.sqrt(), "range to the beacon {range} m");
    assert_eq!(estimate(1), (3.0, 4.0));
}

/// A key out of range is named with what it may be; a start a stream cannot make is
/// refused by its key; what the computer is given reads back as written.
#[test]
fn bad_keys_are_named_and_a_config_reads_back() {
    let e = config(&CONFIG.replace("range_sigma_m = 0.5", "range_sigma_m = -0.5")).checked().unwrap_err();
    assert_eq!(e.to_string(), "key `noise.range_sigma_m` = -0.5: must be a finite number > 0");
    let e = config(&CONFIG.replace("from = \"given\"", "from = \"ranges\"")).unit().unwrap_err();
    assert_eq!(e.key, "initial.from");
    let e = toml::from_str::<StreamConfig>(&CONFIG.replace("y_m = 0.0", "y_m = 0.0\nlat_deg = 1.0")).unwrap_err();
    assert!(e.to_string().contains("unknown field `lat_deg`"), "{e}");
    let c = config(CONFIG);
    assert_eq!(config(&toml::to_string(&c).unwrap()), c);
}

/// A controller given a navigator without what it reads is refused when the
/// configuration is read, by the key that chooses the navigator: behaviours without an
/// iUSBL navigator first (they fell back on the beacon's own position before), FIM
/// approach B without the 6-DOF filter's body velocity; the pairs that work are taken.
#[test]
fn a_controller_refuses_a_navigator_without_what_it_reads() {
    let behaviours = format!("{CONFIG}\n[controller]\nkind = \"behaviours\"\n");
    let e = config(&behaviours).checked().unwrap_err();
    assert_eq!(e.key, "estimators[0].kind");
    assert!(e.to_string().contains("\"rosb\"") && e.allowed.contains("iusbl"), "{e}");
    let iusbl = behaviours.replace("kind = \"rosb\"", "kind = \"iusbl\"");
    assert!(config(&iusbl).checked().is_ok());
    let fim_b = format!("{CONFIG}\n[controller]\nkind = \"fim\"\nmetric = \"approach_b\"\n");
    let e = config(&fim_b).checked().unwrap_err();
    assert_eq!(e.key, "estimators[0].kind");
    assert!(e.allowed.contains("body velocity") && e.allowed.contains("model = \"6dof\""), "{e}");
    let six = fim_b
        .replace("frame = \"ned\"", "frame = \"ned\"\nmodel = \"6dof\"")
        .replace("kind = \"rosb\"", "kind = \"range-ekf\"");
    assert!(config(&six).checked().is_ok(), "{:?}", config(&six).checked());
    assert!(config(&fim_b.replace("approach_b", "approach_a")).checked().is_ok());
}
