//! The error-against-time plot, drawn with plotters into a buffer and saved with `image`.

use super::Row;
use plotters::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;

const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSansMono.ttf");

/// Draw RMSE against seconds on log-log axes, one curve per family, each point labelled.
pub fn plot(rows: &[Row], title: &str, path: &Path) -> Result<(), String> {
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    let (w, h) = (1100u32, 720u32);
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let pos = |f: fn(&Row) -> f64| rows.iter().map(f).filter(|v| *v > 0.0 && v.is_finite());
        let (tmin, tmax) =
            pos(|r| r.seconds).fold((f64::MAX, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
        let (emin, emax) =
            pos(|r| r.rmse).fold((f64::MAX, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
        if tmax <= 0.0 || emax <= 0.0 {
            return Err("nothing to plot".into());
        }
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(
                ((tmin / 1.5)..(tmax * 1.5)).log_scale(),
                ((emin / 1.5)..(emax * 1.5)).log_scale(),
            )
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_max_light_lines(3)
            .y_max_light_lines(3)
            .x_desc("render seconds (median, log)")
            .y_desc("RMSE vs reference (log)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| e.to_string())?;
        let mut families: BTreeMap<&str, Vec<&Row>> = BTreeMap::new();
        let mut order = Vec::new();
        for r in rows {
            if !families.contains_key(r.family.as_str()) {
                order.push(r.family.as_str());
            }
            families.entry(&r.family).or_default().push(r);
        }
        for (i, fam) in order.iter().enumerate() {
            let color = Palette99::pick(i).to_rgba();
            let pts: Vec<(f64, f64)> = families[fam]
                .iter()
                .filter(|r| r.seconds > 0.0 && r.rmse > 0.0)
                .map(|r| (r.seconds, r.rmse))
                .collect();
            chart
                .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(*fam)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(3))
                });
            chart
                .draw_series(pts.iter().map(|p| Circle::new(*p, 4, color.filled())))
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(
                    families[fam]
                        .iter()
                        .filter(|r| r.seconds > 0.0 && r.rmse > 0.0)
                        .map(|r| {
                            Text::new(
                                r.label.clone(),
                                (r.seconds, r.rmse),
                                ("sans-serif", 12).into_font(),
                            )
                        }),
                )
                .map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).ok_or("plot buffer size")?;
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    crate::render::output::write_file(path, &png).map_err(|e| e.to_string())
}
