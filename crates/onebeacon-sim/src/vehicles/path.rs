//! Reference paths made of straight lines and circular arcs, travelled at constant speed.

use nalgebra::Vector2;
use std::f64::consts::PI;

/// Position, velocity and acceleration of the reference at one time (NED, SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reference {
    pub pos: Vector2<f64>,
    pub vel: Vector2<f64>,
    pub acc: Vector2<f64>,
}

#[derive(Debug, Clone, PartialEq)]
enum Segment {
    Line {
        start: Vector2<f64>,
        dir: Vector2<f64>,
        length: f64,
    },
    /// Points `center + radius (cos theta, sin theta)`, theta from `theta0` swept by
    /// `sweep` radians (positive: theta increasing).
    Arc {
        center: Vector2<f64>,
        radius: f64,
        theta0: f64,
        sweep: f64,
    },
}

impl Segment {
    fn length(&self) -> f64 {
        match *self {
            Segment::Line { length, .. } => length,
            Segment::Arc { radius, sweep, .. } => radius * sweep.abs(),
        }
    }

    /// Reference at arc length `s` from the segment's start, travelled at `speed`.
    fn at(&self, s: f64, speed: f64) -> Reference {
        match *self {
            Segment::Line { start, dir, .. } => {
                Reference { pos: start + dir * s, vel: dir * speed, acc: Vector2::zeros() }
            }
            Segment::Arc { center, radius, theta0, sweep } => {
                let sign = sweep.signum();
                let theta = theta0 + sign * s / radius;
                let radial = Vector2::new(theta.cos(), theta.sin());
                Reference {
                    pos: center + radial * radius,
                    vel: Vector2::new(-theta.sin(), theta.cos()) * (sign * speed),
                    acc: -radial * (speed * speed / radius),
                }
            }
        }
    }
}

/// A continuous path of lines and arcs.
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    segments: Vec<Segment>,
    length: f64,
}

impl Path {
    /// A boustrophedon (survey, "lawnmower") path: `legs` straight legs of `leg_length`
    /// metres, the first from `start` along `heading` (rad from north), joined by
    /// half-circle turns of diameter `spacing`; the legs advance to the left of the first
    /// leg when `turn_left`, to the right otherwise.
    pub fn boustrophedon(
        start: Vector2<f64>,
        heading: f64,
        leg_length: f64,
        spacing: f64,
        legs: usize,
        turn_left: bool,
    ) -> Self {
        let d0 = Vector2::new(heading.cos(), heading.sin());
        // left of a heading in NED (x north, y east) is the heading minus 90 deg
        let side = if turn_left { Vector2::new(d0.y, -d0.x) } else { Vector2::new(-d0.y, d0.x) };
        let radius = spacing / 2.0;
        let mut segments = Vec::with_capacity(2 * legs);
        let mut p = start;
        for i in 0..legs {
            let dir = if i % 2 == 0 { d0 } else { -d0 };
            segments.push(Segment::Line { start: p, dir, length: leg_length });
            p += dir * leg_length;
            if i + 1 < legs {
                let center = p + side * radius;
                let r0 = p - center;
                let theta0 = r0.y.atan2(r0.x);
                // turn so that the motion starts along the leg direction
                let tangent = Vector2::new(-theta0.sin(), theta0.cos());
                let sweep = if tangent.dot(&dir) > 0.0 { PI } else { -PI };
                segments.push(Segment::Arc { center, radius, theta0, sweep });
                p += side * spacing;
            }
        }
        Self::from_segments(segments)
    }

    fn from_segments(segments: Vec<Segment>) -> Self {
        let length = segments.iter().map(Segment::length).sum();
        Self { segments, length }
    }

    /// Total length, m.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// The reference after travelling `t` seconds at `speed` from the start. Past the
    /// end the reference goes on straight along the final direction.
    pub fn at_time(&self, t: f64, speed: f64) -> Reference {
        let mut s = (t * speed).max(0.0);
        for seg in &self.segments {
            let l = seg.length();
            if s <= l {
                return seg.at(s, speed);
            }
            s -= l;
        }
        let last = self.segments.last().expect("a path has at least one segment");
        let end = last.at(last.length(), speed);
        Reference { pos: end.pos + end.vel * (s / speed), vel: end.vel, acc: Vector2::zeros() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn boustrophedon_geometry() {
        let p = Path::boustrophedon(Vector2::zeros(), PI / 2.0, 235.0, 20.0, 6, true);
        // 6 legs of 235 m and 5 half circles of radius 10 m
        assert_abs_diff_eq!(p.length(), 6.0 * 235.0 + 5.0 * PI * 10.0, epsilon = 1e-9);
        // end of first leg, then the far side of the first turn (advanced 20 m north)
        let r = p.at_time(235.0, 1.0);
        assert_abs_diff_eq!(r.pos, Vector2::new(0.0, 235.0), epsilon = 1e-9);
        let r = p.at_time(235.0 + PI * 10.0, 1.0);
        assert_abs_diff_eq!(r.pos, Vector2::new(20.0, 235.0), epsilon = 1e-9);
        assert_abs_diff_eq!(r.vel, Vector2::new(0.0, -1.0), epsilon = 1e-9);
        // mid-turn: east-most point, heading north, centripetal acceleration west
        let r = p.at_time(235.0 + PI * 5.0, 1.0);
        assert_abs_diff_eq!(r.pos, Vector2::new(10.0, 245.0), epsilon = 1e-9);
        assert_abs_diff_eq!(r.vel, Vector2::new(1.0, 0.0), epsilon = 1e-9);
        assert_abs_diff_eq!(r.acc, Vector2::new(0.0, -0.1), epsilon = 1e-9);
        // the last leg ends 100 m north of the start, at the start's east
        let r = p.at_time(p.length(), 1.0);
        assert_abs_diff_eq!(r.pos, Vector2::new(100.0, 0.0), epsilon = 1e-9);
    }

    #[test]
    fn velocity_is_the_derivative_of_position() {
        let p = Path::boustrophedon(Vector2::new(5.0, -3.0), 0.3, 50.0, 12.0, 4, false);
        for t in [1.0, 30.0, 55.0, 80.0, 120.0, 170.0] {
            let h = 1e-5;
            let (a, b) = (p.at_time(t - h, 1.3), p.at_time(t + h, 1.3));
            let r = p.at_time(t, 1.3);
            assert_abs_diff_eq!((b.pos - a.pos) / (2.0 * h), r.vel, epsilon = 1e-6);
            assert_abs_diff_eq!(r.vel.norm(), 1.3, epsilon = 1e-12);
        }
    }
}
