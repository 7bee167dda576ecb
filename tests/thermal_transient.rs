//! `dataset.thermal = "transient"` end to end: the images' states lie on the orbit
//! (eclipse times within the shadow, sunlit ones after it), `metadata.jsonl` records
//! them, and eclipse targets are warmer than the steady eclipse state of the same file.

mod cli_common;

use std::fs;

use cli_common::run;

/// Two eclipse poses and one sunlit, coarse meshes and no Earth to keep debug quick.
const TRANSIENT: &str = r#"
[dataset]
name = "transient"
seed = 5
thermal_states = 3
thermal = "transient"

[earth_model]
mesh_deg = 1.0
days = 1

[[scene]]
count = 3
mode = "radiometry"
illumination = ["eclipse", "sunlit", "eclipse"]
range_m = 30.0
resolution_m = 0.2
earth = false
"#;

fn records(config: &str) -> Vec<serde_json::Value> {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("scenes.toml");
    fs::write(&path, config).unwrap();
    let out = tmp.path().join("out");
    let o = run(&[
        "render",
        "--config",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    fs::read_to_string(out.join("metadata.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn transient_states_are_recorded_and_warmer_in_eclipse() {
    let transient = records(TRANSIENT);
    let steady = records(&TRANSIENT.replace("\"transient\"", "\"steady\""));
    assert_eq!(transient.len(), 3);
    for (t, s) in transient.iter().zip(&steady) {
        let time = t["orbit_time_s"].as_f64().unwrap();
        let shadow = t["eclipse_duration_s"].as_f64().unwrap();
        // The reference orbit: 19.9 % of 11 280 s in shadow.
        assert!((shadow - 2248.4).abs() < 1.0, "{shadow}");
        let t_min = t["target_temperature_k"][0].as_f64().unwrap();
        match t["illumination"].as_str().unwrap() {
            "eclipse" => {
                assert!(time > 0.0 && time < shadow, "{time}");
                assert!(t["sun_dir_camera"].is_null());
                let s_max = s["target_temperature_k"][1].as_f64().unwrap();
                assert!(t_min > s_max, "transient {t_min} K vs steady max {s_max} K");
            }
            _ => {
                assert!(time > shadow && time < 11_281.0, "{time}");
                assert!(!t["sun_dir_camera"].is_null());
            }
        }
        assert!(
            s.get("orbit_time_s").is_none(),
            "steady states carry no orbit time"
        );
    }
}
