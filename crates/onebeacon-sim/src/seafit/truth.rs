//! A reference track read between its rows: position linear in time, heading along the
//! shorter turn; nothing outside its first and last row.

use onebeacon::geo::wrap_angle as wrap;

pub(crate) struct Track {
    rows: Vec<(f64, [f64; 2], Option<f64>)>,
}

impl Track {
    /// A track of rows (time, north and east, heading), sorted by time here.
    pub fn new(mut rows: Vec<(f64, [f64; 2], Option<f64>)>) -> Self {
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        Self { rows }
    }

    /// The position and heading at `t`, None outside the rows.
    pub fn at(&self, t: f64) -> Option<([f64; 2], Option<f64>)> {
        let (first, last) = (self.rows.first()?, self.rows.last()?);
        if t < first.0 || t > last.0 {
            return None;
        }
        let k = self.rows.partition_point(|r| r.0 <= t).saturating_sub(1);
        let a = self.rows[k];
        let Some(b) = self.rows.get(k + 1).filter(|b| b.0 > a.0) else { return Some((a.1, a.2)) };
        let f = (t - a.0) / (b.0 - a.0);
        let p = [a.1[0] + f * (b.1[0] - a.1[0]), a.1[1] + f * (b.1[1] - a.1[1])];
        let h = match (a.2, b.2) {
            (Some(x), Some(y)) => Some(wrap(x + f * wrap(y - x))),
            _ => None,
        };
        Some((p, h))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_track_is_read_between_its_rows_and_across_north() {
        let t = Track::new(vec![(1.0, [0.0, 0.0], Some(3.1)), (0.0, [2.0, 0.0], None), (3.0, [4.0, 2.0], Some(-3.1))]);
        assert_eq!(t.at(-0.1), None);
        assert_eq!(t.at(3.5), None);
        assert_eq!(t.at(0.5), Some(([1.0, 0.0], None)));
        let (p, h) = t.at(2.0).unwrap();
        assert_eq!(p, [2.0, 1.0]);
        // halfway from 3.1 to -3.1 the short way: through pi
        assert!((h.unwrap().abs() - std::f64::consts::PI).abs() < 1e-12, "{h:?}");
        assert_eq!(t.at(3.0), Some(([4.0, 2.0], Some(-3.1))));
    }
}
