//! Log-log convergence plots as SVG text (plotters; text is left to the browser's fonts).

use plotters::prelude::*;

/// One line of a plot: a label and its (x, y) points, both positive.
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Points in drawing order.
    pub points: Vec<(f64, f64)>,
}

/// Distinct colours for up to eight series (then they repeat).
const COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
    RGBColor(140, 86, 75),
    RGBColor(127, 127, 127),
];

/// A log-log line plot of `series`, `width × height` pixels.
pub fn log_log_svg(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    (width, height): (u32, u32),
) -> Result<String, String> {
    let points = || series.iter().flat_map(|s| s.points.iter().copied());
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let (xs, ys): (Vec<f64>, Vec<f64>) = points()
        .filter(|&(x, y)| positive(x) && positive(y))
        .unzip();
    if xs.is_empty() {
        return Err(format!("{title}: nothing to plot"));
    }
    let range = |v: &[f64]| {
        let (lo, hi) = v
            .iter()
            .fold((f64::MAX, f64::MIN), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        (lo / 1.15)..(hi * 1.15)
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        let error = |e: DrawingAreaErrorKind<_>| format!("{title}: {e}");
        root.fill(&WHITE).map_err(error)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(64)
            .build_cartesian_2d(range(&xs).log_scale(), range(&ys).log_scale())
            .map_err(error)?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .x_labels(5)
            .y_labels(6)
            .x_label_formatter(&|x| format!("{x:.2e}"))
            .y_label_formatter(&|y| format!("{y:.1e}"))
            .draw()
            .map_err(error)?;
        for (i, s) in series.iter().enumerate() {
            let colour = COLOURS[i % COLOURS.len()];
            let points: Vec<(f64, f64)> = s
                .points
                .iter()
                .copied()
                .filter(|&(x, y)| positive(x) && positive(y))
                .collect();
            chart
                .draw_series(LineSeries::new(points, colour.stroke_width(2)))
                .map_err(error)?
                .label(s.label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(error)?;
        root.present().map_err(error)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plots_have_a_line_per_series_and_the_labels() {
        let series = vec![
            Series {
                label: "off".into(),
                points: vec![(1.0, 0.1), (2.0, 0.05), (4.0, 0.025)],
            },
            Series {
                label: "aggressive".into(),
                points: vec![(1.0, 0.08), (2.0, 0.04), (0.0, 1.0)],
            },
        ];
        let svg = log_log_svg("relMSE", "seconds", "relMSE", &series, (480, 320)).unwrap();
        assert!(svg.starts_with("<svg"), "{}", &svg[..40.min(svg.len())]);
        // Each series' colour draws its line and its legend mark.
        for colour in ["#1F77B4", "#D62728"] {
            assert!(svg.matches(colour).count() >= 2, "{colour} in {svg}");
        }
        assert!(!svg.contains("#2CA02C"), "a third series appeared");
        assert!(svg.contains("aggressive") && svg.contains("seconds"));
        assert!(log_log_svg("t", "x", "y", &[], (100, 100)).is_err());
    }
}
