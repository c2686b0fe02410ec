//! The shear wall's drawings: the crack map as text and SVG, and the load–travel curves.

use super::*;

/// The damage as text: the wall from the top, one line per bed-joint level and one per course
/// (its head joints), 18 columns of 55 mm; `#` a joint that has lost more than half its
/// strength, `+` one that has lost more than 1 %, `.` intact.
pub(super) fn crack_map(damage: &[JointDamage]) -> String {
    let (rows, cols) = (2 * COURSES + 1, 18);
    let mut grid = vec![vec![' '; cols]; rows];
    let mark = |lost: Real| {
        if lost > 0.5 {
            '#'
        } else if lost > 0.01 {
            '+'
        } else {
            '.'
        }
    };
    let cell = |x: Real| ((x / (LENGTH / cols as Real)).floor() as usize).min(cols - 1);
    for d in damage {
        let zc = 0.5 * (d.z.0 + d.z.1);
        let row = ((zc / (0.5 * COURSE_HEIGHT)).round() as usize).min(rows - 1);
        let c = mark(d.lost);
        let cols = cell(d.x.0.max(0.0))..=cell(d.x.1.min(LENGTH - 1e-9));
        for g in &mut grid[row][cols] {
            if *g == ' ' || c == '#' || (c == '+' && *g == '.') {
                *g = c;
            }
        }
    }
    let mut s = String::new();
    for row in grid.iter().rev() {
        let _ = writeln!(s, "  |{}|", row.iter().collect::<String>());
    }
    s
}

pub(super) fn crack_svg(damage: &[JointDamage], title: &str) -> String {
    let scale = 500.0; // px per m
    let (w, h) = (LENGTH * scale + 40.0, HEIGHT * scale + 60.0);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.0}\" height=\"{h:.0}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"20\" y=\"18\">{title}</text>\n\
         <rect x=\"20\" y=\"40\" width=\"{:.1}\" height=\"{:.1}\" fill=\"#f3e3d3\" stroke=\"#999\"/>\n",
        LENGTH * scale,
        HEIGHT * scale
    );
    let px = |x: Real| 20.0 + x * scale;
    let pz = |z: Real| 40.0 + (HEIGHT - z) * scale;
    for d in damage {
        let colour = if d.lost > 0.5 {
            "#c00000"
        } else if d.lost > 0.01 {
            "#f0a000"
        } else {
            "#bbbbbb"
        };
        let width = if d.lost > 0.01 { 3.0 } else { 1.0 };
        let _ = writeln!(
            s,
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{colour}\" stroke-width=\"{width}\"/>",
            px(d.x.0),
            pz(d.z.0),
            px(d.x.1),
            pz(d.z.1)
        );
    }
    s.push_str("<text x=\"20\" y=\"36\" fill=\"#c00000\">red: lost more than half its strength; orange: more than 1 %</text>\n</svg>\n");
    s
}

/// A curve to plot: its name, its colour and its (travel mm, load kN) points.
pub(super) type NamedCurve<'a> = (&'a str, &'a str, &'a [(Real, Real)]);

/// A plain SVG plot of load (kN) against travel (mm), the curves named, with the test's peak
/// and the ±15 % band.
pub(super) fn curve_svg(curves: &[NamedCurve<'_>]) -> String {
    let (w, h, m) = (720.0, 460.0, 60.0);
    let x_max = curves
        .iter()
        .flat_map(|c| c.2.iter().map(|p| p.0))
        .fold(0.5_f64, f64::max)
        .ceil();
    let y_max = 70.0_f64.max(curves.iter().flat_map(|c| c.2.iter().map(|p| p.1)).fold(0.0, f64::max) * 1.1);
    let px = |x: Real| m + x / x_max * (w - 2.0 * m);
    let py = |y: Real| h - m - y / y_max * (h - 2.0 * m);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n\
         <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n\
         <text x=\"{m}\" y=\"24\">Shear wall J4D: horizontal load against top displacement</text>\n"
    );
    let (lo, hi) = (TEST_PEAK_KN * (1.0 - TOLERANCE), TEST_PEAK_KN * (1.0 + TOLERANCE));
    let _ = writeln!(
        s,
        "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"#e0ecff\"/>",
        px(0.0),
        py(hi),
        w - 2.0 * m,
        py(lo) - py(hi)
    );
    let _ = writeln!(
        s,
        "<line x1=\"{:.1}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#3060c0\" stroke-dasharray=\"6 4\"/>\n\
         <text x=\"{:.1}\" y=\"{:.1}\" fill=\"#3060c0\">test J4D peak {TEST_PEAK_KN} kN ± 15 %</text>",
        px(0.0),
        px(x_max),
        px(0.05 * x_max),
        py(hi) - 4.0,
        y = py(TEST_PEAK_KN)
    );
    // Axes and ticks.
    let _ = writeln!(
        s,
        "<line x1=\"{m}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"black\"/>\n<line x1=\"{m}\" y1=\"{m}\" x2=\"{m}\" y2=\"{:.1}\" stroke=\"black\"/>",
        h - m,
        w - m,
        h - m,
        h - m
    );
    let steps = x_max.round() as usize;
    for k in 0..=steps {
        let x = k as Real;
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{k}</text>",
            px(x),
            h - m + 16.0
        );
    }
    let mut y = 0.0;
    while y <= y_max {
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{y:.0}</text>",
            m - 6.0,
            py(y) + 4.0
        );
        y += 10.0;
    }
    let _ = writeln!(
        s,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">top displacement (mm)</text>\n\
         <text x=\"16\" y=\"{:.1}\" transform=\"rotate(-90 16 {:.1})\" text-anchor=\"middle\">horizontal load (kN)</text>",
        0.5 * w,
        h - 18.0,
        0.5 * h,
        0.5 * h
    );
    for (k, (name, colour, points)) in curves.iter().enumerate() {
        let path: Vec<String> = points
            .iter()
            .map(|p| format!("{:.1},{:.1}", px(p.0), py(p.1)))
            .collect();
        let _ = writeln!(
            s,
            "<polyline fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.5\" points=\"{}\"/>\n\
             <text x=\"{:.1}\" y=\"{:.1}\" fill=\"{colour}\">{name}</text>",
            path.join(" "),
            w - m - 160.0,
            m + 16.0 * (k as Real + 1.0)
        );
    }
    s.push_str("</svg>\n");
    s
}
