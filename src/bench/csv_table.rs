//! The bench's rows as CSV, one row per setting, quoted as CSV readers expect.

use super::Row;

pub(crate) fn csv(rows: &[Row]) -> String {
    const HEADER: [&str; 21] = [
        "case",
        "setting",
        "spp",
        "width",
        "height",
        "primitives",
        "groups",
        "build_s",
        "primary_rays",
        "primary_s",
        "mrays_per_s",
        "render_s",
        "first_render_s",
        "load_s",
        "write_s",
        "whole_s",
        "peak_mib",
        "differing_share_same_spp",
        "rms_same_spp",
        "differing_share_16spp",
        "rms_16spp",
    ];
    let c = |x: Option<f64>| {
        x.filter(|v| v.is_finite())
            .map(|v| format!("{v:.6e}"))
            .unwrap_or_default()
    };
    // The csv crate quotes what needs quoting (a scene's name may hold commas or quotes).
    let mut w = ::csv::Writer::from_writer(Vec::new());
    let mut write = |record: &[String]| w.write_record(record).expect("writing to memory");
    write(&HEADER.map(String::from));
    for r in rows {
        write(&[
            r.case.clone(),
            r.setting.clone(),
            r.spp.to_string(),
            r.width.to_string(),
            r.height.to_string(),
            r.primitives.to_string(),
            r.groups.to_string(),
            format!("{:.6}", r.build_s),
            r.primary_rays.to_string(),
            format!("{:.6}", r.primary_s),
            format!("{:.4}", r.mrays_per_s()),
            c(Some(r.render_s)),
            c(Some(r.first_render_s)),
            c(Some(r.load_s)),
            c(Some(r.write_s)),
            c(Some(r.whole_s())),
            c(r.peak_mib),
            c(r.vs_same.as_ref().map(|x| x.differing_share())),
            c(r.vs_same.as_ref().map(|x| x.rms)),
            c(r.vs_hi.as_ref().map(|x| x.differing_share())),
            c(r.vs_hi.as_ref().map(|x| x.rms)),
        ]);
    }
    String::from_utf8(w.into_inner().expect("writing to memory")).expect("UTF-8 in, UTF-8 out")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene's name may hold commas and quotes: the CSV keeps every field whole.
    #[test]
    fn csv_fields_survive_commas_and_quotes() {
        let row = Row {
            case: r#"my "scene", at 0.9"#.into(),
            setting: "embree".into(),
            spp: 1,
            width: 64,
            height: 32,
            primitives: 7,
            groups: 2,
            build_s: 0.5,
            primary_rays: 2048,
            primary_s: 0.25,
            render_s: 1.0,
            first_render_s: 1.5,
            peak_mib: None,
            load_s: 0.1,
            write_s: 0.2,
            vs_same: None,
            vs_hi: None,
            beside: None,
        };
        let text = csv(&[row]);
        let mut reader = ::csv::Reader::from_reader(text.as_bytes());
        let header = reader.headers().unwrap().clone();
        let record = reader.records().next().unwrap().unwrap();
        assert_eq!(header.len(), record.len());
        assert_eq!(&record[0], r#"my "scene", at 0.9"#);
        assert_eq!(&record[16], "", "no peak memory measured: an empty field");
        assert_eq!(
            &record[15], "2.300000e0",
            "whole = load + build + first render + write"
        );
        assert_eq!(&record[8], "2048");
    }
}
