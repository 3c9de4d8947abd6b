//! `conemesh patches` end to end on the built-in surface and a generated OFF file.

use std::process::Command;

#[test]
fn patches_command_writes_ply_and_json() {
    let dir = tempfile::tempdir().expect("tempdir");
    let ply = dir.path().join("p.ply");
    let js = dir.path().join("p.json");
    let out = Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .args(["patches", "--seed", "3", "-o"])
        .arg(&ply)
        .arg("--json")
        .arg(&js)
        .output()
        .expect("run conemesh");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("every patch certified a disk"), "{stdout}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&js).expect("json")).expect("valid json");
    let n = report["patches"].as_u64().expect("patch count");
    assert!(n >= 2);
    assert_eq!(report["stats"].as_array().map(|a| a.len() as u64), Some(n));
    assert_eq!(report["complete"], serde_json::Value::Bool(true));
    let ply_text = std::fs::read(&ply).expect("ply");
    let head = String::from_utf8_lossy(&ply_text[..ply_text.len().min(600)]).to_string();
    assert!(head.contains("property int patch"), "{head}");

    let bad = Command::new(env!("CARGO_BIN_EXE_conemesh"))
        .args(["patches", "--strategy", "nope"])
        .output()
        .expect("run conemesh");
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("unknown patch strategy `nope`"));
}
