//! CSV histories: `time [s],step,<monitor> [unit],...`, one row per sample (RFC 4180: a header
//! field holding a comma, a double quote or a line break is quoted, its quotes doubled).

use std::fmt::Write as _;
use std::path::Path;

use crate::error::Result;
use crate::monitor::History;

/// Renders a history as CSV text: a header `time [s],step,name [unit],...` then one row per
/// sample, numbers in shortest round-trip form. Monitor names are written as given; a header
/// field that holds a comma, a double quote or a line break is quoted as RFC 4180 says
/// (`"a ""b"", c [J]"`), so every record has one field per column whatever the names.
///
/// ```
/// use voussoir::prelude::*;
/// let mut model: Model = Model::new(ModelParameters::default())?;
/// model.set_joint_law(MaterialId(0), MaterialId(0), CoulombSlip::dry(1e9, 4e8, 30.0)?)?;
/// model.add_block(RigidBlock::cuboid("b", Vector::ZERO, Vector::splat(0.1), 2000.0)?)?;
/// let mut recorder = voussoir::monitor::Recorder::new(1);
/// recorder.add_monitor(&model, "kinetic", Monitor::Energy(EnergyTerm::Kinetic))?;
/// model.run_steps_observed(3, &mut recorder)?;
/// let csv = voussoir::io::csv::history_to_csv(recorder.history());
/// assert!(csv.starts_with("time [s],step,kinetic [J]\n"));
/// assert_eq!(csv.lines().count(), 4);
/// # Ok::<(), voussoir::Error>(())
/// ```
pub fn history_to_csv(history: &History) -> String {
    let mut out = String::from("time [s],step");
    for (name, unit) in history.names().iter().zip(history.units()) {
        out.push(',');
        push_field(&mut out, &format!("{name} [{unit}]"));
    }
    out.push('\n');
    // A history is consistent (every column as long as `steps`; deserialisation checks it), but
    // this never indexes out of range: a missing value is written as NaN.
    let value = |v: Option<&f64>| v.copied().unwrap_or(f64::NAN);
    let columns: Vec<&[f64]> = (0..history.names().len())
        .map(|c| history.try_column(crate::monitor::MonitorId(c as u32)).unwrap_or(&[]))
        .collect();
    for (row, step) in history.steps().iter().enumerate() {
        let _ = write!(out, "{:e},{}", value(history.times().get(row)), step);
        for column in &columns {
            let _ = write!(out, ",{:e}", value(column.get(row)));
        }
        out.push('\n');
    }
    out
}

/// Appends one CSV field: as is, or between double quotes with its quotes doubled when it holds
/// a comma, a double quote, a carriage return or a line feed (RFC 4180, section 2).
fn push_field(out: &mut String, field: &str) {
    if field.contains([',', '"', '\n', '\r']) {
        out.push('"');
        out.push_str(&field.replace('"', "\"\""));
        out.push('"');
    } else {
        out.push_str(field);
    }
}

/// Writes [`history_to_csv`] to a file, creating its folder. The file is replaced atomically
/// (written beside it, then renamed): an interrupted write leaves the previous file whole.
///
/// # Errors
/// [`crate::Error::Io`] naming the file.
pub fn write_history(path: &Path, history: &History) -> Result<()> {
    crate::file::write_atomically(path, history_to_csv(history).as_bytes())
}

#[cfg(test)]
mod tests {
    use crate::monitor::History;

    /// `history_to_csv` never indexes out of range, even for a history whose columns do not fit
    /// together (deserialisation refuses those; this one is built by hand): every row has a value
    /// per monitor name, missing values written as NaN.
    #[test]
    fn csv_of_an_inconsistent_history_does_not_panic() {
        let history = History::from_parts_unchecked(
            vec!["a".into(), "b".into(), "c".into()],
            vec!["m".into()],
            vec![10, 20, 30],
            vec![0.1],
            vec![vec![1.0, 2.0], vec![]],
        );
        let csv = super::history_to_csv(&history);
        assert_eq!(
            csv,
            "time [s],step,a [m]\n1e-1,10,1e0,NaN,NaN\nNaN,20,2e0,NaN,NaN\nNaN,30,NaN,NaN,NaN\n"
        );
    }
}
