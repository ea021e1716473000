//! The figures a point of a variation is judged by, from its run's summary: per observer its
//! tail max |x − x̂|, its output residual's tail max |y − Cx̂| and (an unknown-input estimate)
//! tail max |ŵ − w|; with fault diagnosis the
//! false alarms and, per fault, its detection delay and the share of its time isolated
//! correctly. Each is a named column; a figure a run did not reach is missing (NaN in the CSV).

use crate::summary::Summary;

/// A point's figures, as (column, value) in a fixed order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Figures(pub Vec<(String, Option<f64>)>);

/// Whether a larger value of the figure in `column` is worse (the worst point is its largest);
/// else its smallest is (a share isolated correctly).
pub fn larger_is_worse(column: &str) -> bool {
    !column.starts_with("isolated ")
}

impl Figures {
    /// The figures of a run.
    pub fn of(s: &Summary) -> Figures {
        let mut v = Vec::new();
        for o in &s.observers {
            v.push((format!("tail max|e| {}", o.name), o.tail_max_abs_error));
            v.push((
                format!("tail max|y−Cx̂| {}", o.name),
                o.tail_max_abs_residual,
            ));
            if o.tail_max_abs_input_error.is_some() {
                v.push((
                    format!("tail max|ŵ−w| {}", o.name),
                    o.tail_max_abs_input_error,
                ));
            }
        }
        if let Some(d) = &s.diagnosis {
            v.push(("false alarms".into(), Some(d.false_alarms as f64)));
            for f in &d.faults {
                v.push((format!("delay {} [s]", f.name), f.delay));
                v.push((format!("isolated {}", f.name), f.isolated_fraction));
            }
        }
        Figures(v)
    }

    /// The value of `column`, if this point has it.
    pub fn get(&self, column: &str) -> Option<f64> {
        self.0
            .iter()
            .find(|(c, _)| c == column)
            .and_then(|(_, v)| *v)
    }
}
