//! SVG line plots (plotters, SVG backend only: no system font libraries): several series, axis
//! labels with units, a legend and optional reference markers such as an experiment's value.

use std::path::Path;

use plotters::prelude::*;

use crate::error::{Error, Result};
use crate::io::io_error;

/// One named curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Legend label.
    pub label: String,
    /// `(x, y)` points in drawing order.
    pub points: Vec<(f64, f64)>,
}

/// A reference drawn over the curves.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// A horizontal line at `y` (for example an experimental peak load).
    Horizontal {
        /// Legend label.
        label: String,
        /// Ordinate.
        y: f64,
    },
    /// A single marked point (for example a measured value).
    Point {
        /// Legend label.
        label: String,
        /// Abscissa.
        x: f64,
        /// Ordinate.
        y: f64,
    },
}

/// A line plot: title, axis labels (with units), curves and references.
///
/// ```
/// use voussoir::io::plot::{Curve, LinePlot, Reference};
/// let plot = LinePlot {
///     title: "load–displacement".into(),
///     x_label: "displacement [mm]".into(),
///     y_label: "load [kN]".into(),
///     curves: vec![Curve { label: "model".into(), points: vec![(0.0, 0.0), (1.0, 2.5), (2.0, 2.0)] }],
///     references: vec![Reference::Horizontal { label: "experiment".into(), y: 2.71 }],
/// };
/// let svg = plot.to_svg_string()?;
/// assert!(svg.contains("<svg") && svg.contains("experiment"));
/// # Ok::<(), voussoir::Error>(())
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinePlot {
    /// Title.
    pub title: String,
    /// Horizontal axis label, with its unit.
    pub x_label: String,
    /// Vertical axis label, with its unit.
    pub y_label: String,
    /// The curves.
    pub curves: Vec<Curve>,
    /// Reference lines and points.
    pub references: Vec<Reference>,
}

const SIZE: (u32, u32) = (800, 560);

impl LinePlot {
    /// Renders the plot as an SVG document.
    ///
    /// # Errors
    /// [`Error::Io`] if plotters fails to draw.
    pub fn to_svg_string(&self) -> Result<String> {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
            self.draw(root).map_err(|e| Error::Io {
                path: "(svg)".into(),
                message: format!("plot {:?}: {e}", self.title),
            })?;
        }
        Ok(svg)
    }

    /// Writes the plot to an SVG file, creating its folder.
    ///
    /// # Errors
    /// [`Error::Io`] naming the file.
    pub fn write_svg(&self, path: &Path) -> Result<()> {
        let svg = self.to_svg_string()?;
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| io_error(dir, &e))?;
        }
        std::fs::write(path, svg).map_err(|e| io_error(path, &e))
    }

    fn ranges(&self) -> ((f64, f64), (f64, f64)) {
        let mut xs: Vec<f64> = Vec::new();
        let mut ys: Vec<f64> = Vec::new();
        for c in &self.curves {
            for &(x, y) in &c.points {
                if x.is_finite() && y.is_finite() {
                    xs.push(x);
                    ys.push(y);
                }
            }
        }
        for r in &self.references {
            match *r {
                Reference::Horizontal { y, .. } => ys.push(y),
                Reference::Point { x, y, .. } => {
                    xs.push(x);
                    ys.push(y);
                }
            }
        }
        let span = |v: &[f64]| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if !lo.is_finite() {
                return (0.0, 1.0);
            }
            let pad = if hi > lo {
                0.05 * (hi - lo)
            } else {
                0.5 * lo.abs().max(1.0)
            };
            (lo - pad, hi + pad)
        };
        (span(&xs), span(&ys))
    }

    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, plotters::coord::Shift>) -> std::result::Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(err)?;
        let ((x0, x1), (y0, y1)) = self.ranges();
        let mut chart = ChartBuilder::on(&root)
            .caption(&self.title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(err)?;
        for (k, c) in self.curves.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            chart
                .draw_series(LineSeries::new(c.points.iter().copied(), color.stroke_width(2)))
                .map_err(err)?
                .label(c.label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
        }
        for r in &self.references {
            match r {
                Reference::Horizontal { label, y } => {
                    let style = BLACK.stroke_width(1);
                    chart
                        .draw_series(DashedLineSeries::new(vec![(x0, *y), (x1, *y)], 8, 5, style))
                        .map_err(err)?
                        .label(label.as_str())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
                }
                Reference::Point { label, x, y } => {
                    chart
                        .draw_series(std::iter::once(Cross::new((*x, *y), 7, BLACK.stroke_width(2))))
                        .map_err(err)?
                        .label(label.as_str())
                        .legend(|(x, y)| Cross::new((x + 10, y), 5, BLACK.stroke_width(2)));
                }
            }
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(err)?;
        root.present().map_err(err)?;
        Ok(())
    }
}
