//! The study's report: one self-contained HTML file (images, plots and script inline, no
//! network), and the same tables as Markdown for BENCHMARKS.md.

use super::affinity_figure::{snapshot_svg, SNAPSHOTS};
use super::metrics::{relative_error_colours, rgbe};
use super::plots::{LogLogPlot, Series};
use super::summary::{summary, Measured, SummaryRow};
use super::{ConfigurationResult, Run, StudyResults};
use ais_render::image_io::RgbImage;
use base64::Engine;
use std::fmt::Write;

/// What the report says about the study besides its results.
pub struct ReportContext<'a> {
    /// The scene (a file, or the built-in default scene).
    pub scene: &'a str,
    /// Image size.
    pub resolution: (u32, u32),
    /// Gather rays per camera sample.
    pub rays: u32,
    /// Equal-time budget per run (seconds).
    pub time_budget: f64,
    /// Seeds per configuration.
    pub seeds: u32,
    /// Reference samples per pixel.
    pub reference_spp: u32,
    /// Worker threads.
    pub threads: usize,
    /// The affinity-map figure's pixel.
    pub figure_pixel: (u32, u32),
}

/// The summary tables as Markdown: equal time, then equal rays with the oracle's share.
pub fn markdown_tables(results: &StudyResults, context: &ReportContext) -> String {
    let rows = summary(results, context);
    let mut out = equal_time_table(results, context, &rows);
    let best = (rows.iter())
        .filter_map(|row| row.equal_time.as_ref().map(|time| time.rel_mse.mean))
        .fold(f64::INFINITY, f64::min);
    let floor = results.reference.noise_floor();
    if let Some(warning) = reference_warning(floor, best, context.reference_spp) {
        out.push_str(&warning);
    }
    out.push_str(&equal_rays_table(results, &rows));
    out
}

/// The share of the best equal-time relMSE that the reference's own noise may reach before
/// the study warns: it is subtracted from every relMSE, but its noise stays in the ratios.
const REFERENCE_NOISE_WARNING: f64 = 0.25;

/// A note under the equal-time table when the reference (`reference_spp` samples per pixel,
/// its own relMSE `floor`) is too noisy for the best run it judges (relMSE `best`), with the
/// samples per pixel (a power of two) that would bring its part below a tenth of that.
fn reference_warning(floor: f64, best: f64, reference_spp: u32) -> Option<String> {
    if !(floor > 0.0 && best.is_finite() && floor > REFERENCE_NOISE_WARNING * best) {
        return None;
    }
    // A reference's relMSE falls as 1 / spp. A run at or below the reference's own noise
    // (its relMSE less that noise not above 0) says only that the reference needs many more.
    let factor = if best > 0.0 {
        floor / (0.1 * best)
    } else {
        16.0
    };
    let wanted = (reference_spp as f64 * factor).ceil().min(u32::MAX as f64) as u32;
    let suggested = wanted.checked_next_power_of_two().unwrap_or(u32::MAX);
    let (share, advice) = if best > 0.0 {
        let share = format!(
            "{:.0}% of the best run's ({best:.2e})",
            100.0 * floor / best
        );
        (share, "would bring it below a tenth")
    } else {
        (
            "as large as the best run's".to_string(),
            "at least, is needed",
        )
    };
    Some(format!(
        "\n**The reference is too noisy for these runs**: its own relMSE ({floor:.2e}) is \
         {share}. It is subtracted, but its noise stays in the ratios. A reference of \
         {suggested} samples per pixel (`--reference-spp {suggested}`) {advice}.\n"
    ))
}

/// A ratio, or a dash where it means nothing (a black scene, where both are 0).
fn ratio(ratio: f64) -> String {
    if ratio.is_finite() {
        format!("{ratio:.2}×")
    } else {
        "–".into()
    }
}

/// A mean with its standard error; one seed has none.
fn with_error(measured: Measured) -> String {
    if measured.error.is_finite() {
        format!("{:.3e} ± {:.1e}", measured.mean, measured.error)
    } else {
        format!("{:.3e} (one seed: no error bar)", measured.mean)
    }
}

/// The equal-time table, with its introduction.
fn equal_time_table(
    results: &StudyResults,
    context: &ReportContext,
    rows: &[SummaryRow],
) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Equal time ({:.1} s per run, {} seeds; ratio = baseline relMSE / relMSE, above 1 is \
         better; relMSE less the reference's own noise, {:.2e}, and scaled to the budget: \
         relMSE × time / budget; alike: every pixel's relative error weighted alike, ε = 1e-4 \
         for relMSE's 0.01, so that dark pixels are not hidden; MSE: every pixel's error in \
         radiance alike, so the brightest dominate; both corrected and scaled as relMSE):\n",
        context.time_budget,
        context.seeds,
        results.reference.noise_floor()
    );
    out.push_str("| configuration | spp | ms per spp | nominal rays/pixel | traced rays/pixel | rejected/pixel | AIS KiB/thread | relMSE | ratio | MSE | ratio (MSE) | alike | ratio (alike) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for row in rows {
        let Some(time) = &row.equal_time else {
            continue;
        };
        let _ = writeln!(
            out,
            "| {} | {:.1} | {:.0} | {:.0} | {:.1} | {:.1} | {:.1} | {} | {} | {} | {} | {} | {} |",
            row.name,
            time.spp,
            time.ms_per_spp,
            time.nominal_rays_per_pixel,
            time.traced_rays_per_pixel,
            time.rejected_per_pixel,
            time.ais_kib_per_thread,
            with_error(time.rel_mse),
            ratio(time.ratio),
            with_error(time.mse),
            ratio(time.mse_ratio),
            with_error(time.relative_alike),
            ratio(time.relative_alike_ratio)
        );
    }
    out
}

/// The equal-ray table, with its introduction.
fn equal_rays_table(results: &StudyResults, rows: &[SummaryRow]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "\nEqual rays ({:.0} rays per run, the baseline's median at equal time; relMSE × rays / \
         budget; oracle share = (baseline − relMSE) / (baseline − oracle relMSE); MSE and alike \
         as above):\n",
        results.ray_budget as f64
    );
    out.push_str(
        "| configuration | spp | time (s) | relMSE | ratio | oracle share | MSE | ratio (MSE) | alike | ratio (alike) |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for row in rows {
        let rays = &row.equal_rays;
        let _ = writeln!(
            out,
            "| {} | {:.1} | {:.2} | {} | {} | {} | {} | {} | {} | {} |",
            row.name,
            rays.spp,
            rays.seconds,
            with_error(rays.rel_mse),
            ratio(rays.ratio),
            if rays.oracle_share.is_finite() {
                format!("{:.0}%", 100.0 * rays.oracle_share)
            } else {
                "–".into()
            },
            with_error(rays.mse),
            ratio(rays.mse_ratio),
            with_error(rays.relative_alike),
            ratio(rays.relative_alike_ratio)
        );
    }
    out
}

fn png_data_url(width: usize, height: usize, rgb: &[[u8; 3]]) -> Result<String, String> {
    use image::ImageEncoder;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(
            rgb.as_flattened(),
            width as u32,
            height as u32,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| format!("cannot encode a PNG: {e}"))?;
    Ok(format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    ))
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A canvas showing image `name` from the embedded set, with a caption.
fn figure_canvas(name: &str, caption: &str) -> String {
    format!(
        r#"<figure><canvas class="hdr" data-image="{}"></canvas><figcaption>{}</figcaption></figure>"#,
        escape(name),
        escape(caption)
    )
}

/// A configuration's first run (equal time if it has one): the one its images show.
fn seed0(result: &ConfigurationResult) -> &RgbImage {
    result
        .equal_time
        .first()
        .or(result.equal_rays.first())
        .map(|r| &r.image)
        .expect("every configuration has runs")
}

/// The embedded HDR images, as a JavaScript object: the reference and each configuration's
/// first run.
fn embedded_images(results: &StudyResults) -> String {
    let mut images = String::from("{");
    let mut embed = |name: &str, image: &RgbImage| {
        let _ = write!(
            images,
            "{:?}:{{w:{},h:{},rgbe:\"{}\"}},",
            name,
            image.width,
            image.height,
            base64::engine::general_purpose::STANDARD.encode(rgbe(image))
        );
    };
    embed("reference", &results.reference.image);
    for result in &results.results {
        embed(&result.configuration.name, seed0(result));
    }
    images.push('}');
    images
}

/// The viewer's image choices.
fn image_options(results: &StudyResults) -> String {
    let mut options = String::from(r#"<option value="reference">reference</option>"#);
    for result in &results.results {
        let _ = write!(
            options,
            r#"<option value="{0}">{0}</option>"#,
            escape(&result.configuration.name)
        );
    }
    options
}

/// A false-colour relative-error image per configuration.
fn error_maps(results: &StudyResults) -> Result<String, String> {
    let (width, height) = (
        results.reference.image.width,
        results.reference.image.height,
    );
    let mut errors = String::new();
    for result in &results.results {
        let url = png_data_url(
            width,
            height,
            &relative_error_colours(seed0(result), &results.reference.image, 0.5),
        )?;
        let run = if result.equal_time.is_empty() {
            "equal rays"
        } else {
            "equal time"
        };
        let _ = write!(
            errors,
            r#"<figure><img class="error-map" src="{url}" width="{width}" height="{height}" alt="relative error of {0}"><figcaption>{0} ({run}, seed 0)</figcaption></figure>"#,
            escape(&result.configuration.name)
        );
    }
    Ok(errors)
}

/// The log-log plots of relMSE against time and against rays.
fn convergence_plots(results: &StudyResults) -> Result<(String, String), String> {
    let curves = |pick: &dyn Fn(&ConfigurationResult) -> &[Run],
                  x: &dyn Fn(&super::CurvePoint) -> f64| {
        results
            .results
            .iter()
            .filter(|r| !pick(r).is_empty())
            .map(|r| Series {
                label: r.configuration.name.clone(),
                points: pick(r)[0].curve.iter().map(|p| (x(p), p.rel_mse)).collect(),
            })
            .collect::<Vec<_>>()
    };
    let plot = |title, x_label| LogLogPlot {
        title,
        x_label,
        y_label: "relMSE",
        size: (640, 400),
    };
    let time_plot = plot(
        "relMSE against render time (equal-time runs, seed 0)",
        "seconds",
    )
    .svg(&curves(&|r| &r.equal_time, &|p| p.seconds))?;
    let rays_plot = plot(
        "relMSE against rays traced (equal-ray runs, seed 0)",
        "rays",
    )
    .svg(&curves(&|r| &r.equal_rays, &|p| p.rays as f64))?;
    Ok((time_plot, rays_plot))
}

/// The canvases of the named configurations that the study ran, in order.
fn figure_group(results: &StudyResults, names: &[&str]) -> String {
    names
        .iter()
        .filter_map(|name| {
            results
                .results
                .iter()
                .find(|r| r.configuration.name == *name)
        })
        .map(|r| figure_canvas(&r.configuration.name, &r.configuration.label))
        .collect()
}

/// The affinity-map figure: the pixel's map after each snapshot's rays.
fn affinity_maps(results: &StudyResults) -> String {
    match &results.figure {
        Some(snapshots) => snapshots
            .iter()
            .zip(SNAPSHOTS)
            .map(|(s, n)| {
                format!(
                    "<figure>{}<figcaption>after {n} rays</figcaption></figure>",
                    snapshot_svg(s, 24)
                )
            })
            .collect(),
        None => "<p>The chosen pixel sees no gather point.</p>".into(),
    }
}

/// The reference's provenance and noise, for the report's text.
fn reference_note(results: &StudyResults) -> String {
    format!(
        "{}; its own noise would add {:.2e} to every relMSE, which is subtracted",
        if results.reference.cached {
            " (from the cache)"
        } else {
            ""
        },
        results.reference.noise_floor()
    )
}

/// The whole report as HTML.
pub fn html(results: &StudyResults, context: &ReportContext) -> Result<String, String> {
    let (time_plot, rays_plot) = convergence_plots(results)?;
    let (x, y) = context.figure_pixel;
    let placement = [
        "mis-off",
        "mis-off-random",
        "mis-aggressive",
        "mis-aggressive-random",
    ];
    let substitutions: [(&str, String); 20] = [
        ("SCENE", escape(context.scene)),
        ("WIDTH", context.resolution.0.to_string()),
        ("HEIGHT", context.resolution.1.to_string()),
        ("RAYS", context.rays.to_string()),
        ("BUDGET", format!("{:.1}", context.time_budget)),
        ("SEEDS", context.seeds.to_string()),
        ("REFERENCE_SPP", context.reference_spp.to_string()),
        ("REFERENCE_CACHED", reference_note(results)),
        ("THREADS", context.threads.to_string()),
        ("OPTIONS", image_options(results)),
        ("ERRORS", error_maps(results)?),
        ("TIME_PLOT", time_plot),
        ("RAYS_PLOT", rays_plot),
        (
            "FIGURE_UNIFORM",
            figure_group(results, &["uniform-off", "mis-off", "mis-aggressive"]),
        ),
        (
            "FIGURE_MODES",
            figure_group(results, &["mis-off", "mis-aggressive", "mis-conservative"]),
        ),
        ("FIGURE_PLACEMENT", figure_group(results, &placement)),
        ("MAPS", affinity_maps(results)),
        ("PIXEL", format!("({x}, {y})")),
        (
            "TABLES",
            markdown_to_html_tables(&markdown_tables(results, context)),
        ),
        ("IMAGES", embedded_images(results)),
    ];
    // Markers are replaced in this order; none of the inserted texts contains a later marker.
    let mut html = include_str!("report_template.html").to_string();
    for (marker, text) in substitutions {
        html = html.replace(&format!("%%{marker}%%"), &text);
    }
    Ok(html)
}

/// Turns the Markdown tables and their introductory lines into HTML.
fn markdown_to_html_tables(markdown: &str) -> String {
    let mut html = String::new();
    let mut in_table = false;
    for line in markdown.lines() {
        if line.starts_with('|') {
            let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
            if cells.iter().all(|c| c.chars().all(|ch| ch == '-')) {
                continue;
            }
            if !in_table {
                html.push_str("<table><tr>");
                for c in &cells {
                    let _ = write!(html, "<th>{}</th>", escape(c));
                }
                html.push_str("</tr>");
                in_table = true;
            } else {
                html.push_str("<tr>");
                for c in &cells {
                    let _ = write!(html, "<td>{}</td>", escape(c));
                }
                html.push_str("</tr>");
            }
        } else {
            if in_table {
                html.push_str("</table>");
                in_table = false;
            }
            if !line.trim().is_empty() {
                let _ = write!(html, "<p>{}</p>", escape(line));
            }
        }
    }
    if in_table {
        html.push_str("</table>");
    }
    html
}

/// Writes the report into `folder`: `index.html`, `tables.md`, and the reference and each
/// configuration's first image as EXR in `images/`. Returns the HTML's path.
pub fn write(
    folder: &std::path::Path,
    results: &StudyResults,
    context: &ReportContext,
) -> Result<std::path::PathBuf, String> {
    let images = folder.join("images");
    std::fs::create_dir_all(&images)
        .map_err(|e| format!("{}: cannot create the folder: {e}", images.display()))?;
    let exr = |name: &str, image: &RgbImage| {
        ais_render::image_io::write_exr(&images.join(format!("{name}.exr")), image)
            .map_err(|e| e.to_string())
    };
    exr("reference", &results.reference.image)?;
    for result in &results.results {
        let first = result.equal_time.first().or(result.equal_rays.first());
        if let Some(run) = first {
            exr(&result.configuration.name, &run.image)?;
        }
    }
    super::write_text(
        &folder.join("tables.md"),
        &markdown_tables(results, context),
    )?;
    let path = folder.join("index.html");
    super::write_text(&path, &html(results, context)?)?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reference_as_noisy_as_the_runs_is_named_with_the_samples_it_needs() {
        // The sunlit room at n = 16: a reference of 128 spp against runs of about its noise.
        let warning = reference_warning(1.35e-3, 1.5e-3, 128).expect("a warning");
        assert!(warning.contains("90%"), "{warning}");
        // 128 × 1.35e-3 / 1.5e-4 = 1152 samples, rounded up to a power of two.
        assert!(warning.contains("`--reference-spp 2048`"), "{warning}");
        // A reference at a tenth of the best run's relMSE says nothing.
        assert_eq!(reference_warning(1.5e-4, 1.5e-3, 1024), None);
        // Nor where no run has a relMSE to compare with.
        assert_eq!(reference_warning(1e-3, f64::INFINITY, 128), None);
        assert_eq!(reference_warning(0.0, 1e-3, 128), None);
        // Runs at the reference's own noise: many more samples.
        let warning = reference_warning(1e-3, -1e-5, 128).expect("a warning");
        assert!(warning.contains("as large as the best run's"), "{warning}");
        assert!(warning.contains("`--reference-spp 2048`"), "{warning}");
        // Beyond the largest power of two a u32 holds: the largest count, not an overflow.
        let warning = reference_warning(1.0, 1e-9, u32::MAX).expect("a warning");
        assert!(
            warning.contains(&format!("`--reference-spp {}`", u32::MAX)),
            "{warning}"
        );
    }
}
