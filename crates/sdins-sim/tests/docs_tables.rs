//! Generated documentation tables stay equal to the code: the grade table and the
//! `[imu.errors]` keys in docs/imu-errors.md. Regenerate with
//! `SDINS_WRITE_DOCS=1 cargo test -p sdins-sim --test docs_tables`.
#![allow(clippy::unwrap_used)]

fn replace_between(doc: &str, tag: &str, body: &str) -> String {
    let (open, close) = (format!("<!-- {tag} -->\n"), format!("<!-- /{tag} -->"));
    let a = doc
        .find(&open)
        .unwrap_or_else(|| panic!("docs/imu-errors.md lacks {open}"))
        + open.len();
    let b = doc
        .find(&close)
        .unwrap_or_else(|| panic!("docs/imu-errors.md lacks {close}"));
    format!("{}{}{}", &doc[..a], body, &doc[b..])
}

#[test]
fn imu_errors_doc_has_the_generated_tables() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/imu-errors.md");
    let doc = std::fs::read_to_string(path).unwrap();
    let want = replace_between(
        &replace_between(
            &doc,
            "grades",
            &sdins_sim::sensors::imu_error::presets::markdown_table(),
        ),
        "keys",
        &sdins_sim::sensors::imu_error::keys_markdown(),
    );
    if std::env::var_os("SDINS_WRITE_DOCS").is_some() {
        std::fs::write(path, &want).unwrap();
    }
    assert!(
        doc == want,
        "docs/imu-errors.md is out of date: run SDINS_WRITE_DOCS=1 cargo test -p sdins-sim --test docs_tables"
    );
}

#[test]
fn the_error_analysis_reads_the_one_grade_table() {
    use sdins_sim::analysis::error_analysis::grades::grade_by_name;
    use sdins_sim::sensors::imu_error::presets::{preset, GRADES};
    for g in &GRADES {
        let m = preset(g.name).unwrap();
        let e = grade_by_name(g.name).unwrap();
        assert_eq!(m.gyro_bias_turn_on_dph, [e.gyro_bias_turn_on_dph; 3]);
        assert_eq!(m.accel_bias_turn_on_ug, [e.accel_bias_turn_on_ug; 3]);
        assert_eq!(m.gyro_arw_dpsh, [e.gyro_arw_dpsh; 3]);
        assert_eq!(m.accel_vrw_ugpsqrthz, [e.accel_vrw_ugpsqrthz; 3]);
    }
}
