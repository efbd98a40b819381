//! The sun's irradiance table of the physical sky ([`super::sky`]): `sky_sun_table.csv`, written
//! by `scripts/sunsky_sun_table.py` from Mitsuba 3's `sunsky` (Hosek–Wilkie solar model data
//! (c) 2012-2013 Lukas Hosek and Alexander Wilkie, 3-clause BSD: the license in Mitsuba 3's
//! data/sunsky/LICENSE). Compiled in and parsed once, on first use.

use std::sync::LazyLock;

/// Turbidities 1, 2, …, 10.
pub(crate) const TURBIDITIES: usize = 10;
/// Solar elevations 2°, 5°, …, 89°.
pub(crate) const ELEVATIONS: usize = 30;

/// The sun's irradiance (W/m², linear sRGB, Mitsuba 3's RGB `sunsky` units) on a surface facing
/// it, per turbidity and solar elevation node: `[turbidity − 1][(elevation° − 2) / 3]`.
pub(crate) type SunTable = [[[f32; 3]; ELEVATIONS]; TURBIDITIES];

/// The table (parsed from `sky_sun_table.csv` the first time it is asked for).
pub(crate) fn sun_irradiance_table() -> &'static SunTable {
    static TABLE: LazyLock<SunTable> = LazyLock::new(|| parse(include_str!("sky_sun_table.csv")));
    &TABLE
}

/// Reads the CSV: `#` comment lines, a header, then one row `turbidity,elevation_deg,r,g,b` per
/// node, in order. The text is compiled in, so a malformed row is a build's mistake: it panics
/// with the row.
fn parse(text: &str) -> SunTable {
    let mut table = [[[0.0; 3]; ELEVATIONS]; TURBIDITIES];
    let rows = text.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty()).skip(1);
    let mut count = 0;
    for (k, line) in rows.enumerate() {
        let fields: Vec<&str> = line.split(',').collect();
        let node: Option<(usize, usize, Vec<f32>)> = (|| {
            let t: usize = fields.first()?.parse().ok()?;
            let e: usize = fields.get(1)?.parse().ok()?;
            let rgb = fields.get(2..5)?.iter().map(|v| v.parse().ok()).collect::<Option<Vec<f32>>>()?;
            Some((t, e, rgb))
        })();
        let (t, e, rgb) = node.unwrap_or_else(|| panic!("sky_sun_table.csv: malformed row '{line}'"));
        let (ti, ei) = (k / ELEVATIONS, k % ELEVATIONS);
        assert!(
            fields.len() == 5 && ti < TURBIDITIES && t == ti + 1 && e == 2 + 3 * ei,
            "sky_sun_table.csv: row '{line}' is not the node (turbidity {}, elevation {}°)",
            ti + 1,
            2 + 3 * ei
        );
        table[ti][ei] = [rgb[0], rgb[1], rgb[2]];
        count += 1;
    }
    assert_eq!(count, TURBIDITIES * ELEVATIONS, "sky_sun_table.csv: rows");
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every node is present, in order, and physically plausible: the sun's irradiance at the
    /// ground is positive in green (every channel above 5° elevation) and below the solar
    /// constant's ~1361 W/m² times Mitsuba's RGB scale (a generous bound of 10 in its units).
    #[test]
    fn the_compiled_in_table_parses_to_every_node() {
        let table = sun_irradiance_table();
        for row in table {
            for (ei, rgb) in row.iter().enumerate() {
                assert!(rgb[1] > 0.0 && rgb.iter().all(|&c| c < 10.0), "{rgb:?}");
                if ei >= 2 {
                    assert!(rgb.iter().all(|&c| c > 0.0), "{rgb:?}");
                }
            }
        }
    }

    #[test]
    #[should_panic(expected = "not the node")]
    fn a_row_out_of_order_is_refused() {
        parse("turbidity,elevation_deg,r,g,b\n1,5,1,1,1\n");
    }
}
