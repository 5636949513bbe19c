//! `report.html`: what accuracy costs, as one self-contained page (images embedded, nothing
//! fetched from a network).
//!
//! It holds: each rung's image beside the reference with a slider between them; per-pixel
//! error heatmaps (relative squared error and FLIP) with colour bars; the error-against-time
//! plot as SVG, where hovering a point names the rung and clicking it shows the rung; a table of
//! time, rays, RMSE, relMSE, mean FLIP, bias^2 and variance per rung; an "equal error" view
//! (for a chosen RMSE, the time each family needs to reach it, interpolated on the log-log
//! curve); the price of each effect of the scene; where each rung's time goes (time per
//! pixel, squared error per pixel, and variance times time, the inverse efficiency); and the
//! samples of each rung that stand out most above the reference, circled on its image, with
//! their paths.

use super::metrics::{flip, rel_se_map, se_map};
use super::{Measured, REPORT_FIREFLIES, Row};
use crate::render::film::Image;
use crate::render::output::{Transfer, to_rgb8};
use crate::shader::record::Event;
use std::fmt::Write;

/// What switching one effect off saves and costs.
#[derive(Clone, Debug, serde::Serialize)]
pub struct EffectPrice {
    /// The effect switched off (empty for the render with every effect the scene needs).
    pub effect: String,
    /// Render seconds.
    pub seconds: f64,
    /// Rays traced.
    pub rays: u64,
    /// RMSE against the reference.
    pub rmse: f64,
    /// Mean FLIP against the reference.
    pub flip: f64,
}

/// Everything the report shows.
pub struct Report<'a> {
    /// Title: the scene and the film.
    pub title: String,
    /// The reference image.
    pub reference: &'a Image,
    /// What the reference is and how noisy (said plainly when its noise is not small).
    pub reference_note: String,
    /// The measured rungs.
    pub rungs: &'a [Measured],
    /// The price of each effect of the scene's own shader.
    pub effects: &'a [EffectPrice],
    /// PNG transfer of the images.
    pub transfer: Transfer,
}

/// Standard base64 of `bytes`.
pub fn base64(bytes: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

fn png_uri(img: &image::RgbImage) -> String {
    let mut v = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut v), image::ImageFormat::Png)
        .expect("PNG into memory");
    format!("data:image/png;base64,{}", base64(&v))
}

/// Values through FLIP's magma colour map, scaled so that `max` is the top of the bar.
fn magma(values: &[f32], w: u32, h: u32, max: f32) -> image::RgbImage {
    let scaled: Vec<f32> = values
        .iter()
        .map(|v| (v / max.max(1e-12)).clamp(0.0, 1.0))
        .collect();
    let f = nv_flip::FlipImageFloat::with_data(w, h, &scaled);
    let c = f.apply_color_lut(&nv_flip::magma_lut());
    image::RgbImage::from_raw(w, h, c.to_vec()).expect("size")
}

/// A colour bar from 0 to `max`.
fn colour_bar(max: f32, label: &str) -> String {
    let ramp: Vec<f32> = (0..256).map(|i| i as f32 / 255.0 * max).collect();
    let img = magma(&ramp, 256, 1, max);
    format!(
        "<div class=\"bar\"><span>0</span><img src=\"{}\" alt=\"colour bar\" width=\"256\" \
         height=\"12\"><span>{max:.3} {label}</span></div>",
        png_uri(&img)
    )
}

/// A colour bar from 0 to a maximum that the page writes into the span `id` (a scale that
/// changes with the rung shown).
fn colour_bar_labelled(id: &str, label: &str) -> String {
    let ramp: Vec<f32> = (0..256).map(|i| i as f32 / 255.0).collect();
    format!(
        "<div class=\"bar\"><span>0</span><img src=\"{}\" alt=\"colour bar\" width=\"256\" \
         height=\"12\"><span><span id=\"{id}\"></span> {label}</span></div>",
        png_uri(&magma(&ramp, 256, 1, 1.0))
    )
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('"', "&quot;")
}

/// The plot as SVG: RMSE against seconds on log-log axes, one colour per family; each point
/// has a title (shown on hover) and selects its rung when clicked.
fn plot_svg(rows: &[&Row]) -> String {
    let (w, h, m) = (720.0, 440.0, 60.0);
    let pos: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r.seconds.max(1e-6).log10(), r.rmse.max(1e-9).log10()))
        .collect();
    let (x0, x1) = pos
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (y0, y1) = pos
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let (x0, x1) = (x0.floor(), x1.ceil().max(x0.floor() + 1.0));
    let (y0, y1) = (y0.floor(), y1.ceil().max(y0.floor() + 1.0));
    let sx = |x: f64| m + (x - x0) / (x1 - x0) * (w - 2.0 * m);
    let sy = |y: f64| h - m - (y - y0) / (y1 - y0) * (h - 2.0 * m);
    let mut s = format!(
        "<svg id=\"plot\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" \
         xmlns=\"http://www.w3.org/2000/svg\" font-size=\"12\">\
         <rect x=\"{m}\" y=\"{m}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#888\"/>",
        w - 2.0 * m,
        h - 2.0 * m
    );
    for d in (x0 as i32)..=(x1 as i32) {
        let x = sx(d as f64);
        let _ = write!(
            s,
            "<line x1=\"{x}\" y1=\"{m}\" x2=\"{x}\" y2=\"{}\" stroke=\"#eee\"/>\
             <text x=\"{x}\" y=\"{}\" text-anchor=\"middle\">1e{d} s</text>",
            h - m,
            h - m + 18.0
        );
    }
    for d in (y0 as i32)..=(y1 as i32) {
        let y = sy(d as f64);
        let _ = write!(
            s,
            "<line x1=\"{m}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"#eee\"/>\
             <text x=\"{}\" y=\"{y}\" text-anchor=\"end\" dy=\"4\">1e{d}</text>",
            w - m,
            m - 6.0
        );
    }
    let _ = write!(
        s,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">seconds</text>\
         <text x=\"14\" y=\"{}\" transform=\"rotate(-90 14 {})\" text-anchor=\"middle\">RMSE</text>",
        w / 2.0,
        h - 12.0,
        h / 2.0,
        h / 2.0
    );
    const COLOURS: [&str; 8] = [
        "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf",
    ];
    let mut families: Vec<&str> = Vec::new();
    for r in rows {
        if !families.contains(&r.family.as_str()) {
            families.push(&r.family);
        }
    }
    for (fi, fam) in families.iter().enumerate() {
        let c = COLOURS[fi % COLOURS.len()];
        let pts: Vec<String> = rows
            .iter()
            .zip(&pos)
            .filter(|(r, _)| r.family == *fam)
            .map(|(_, p)| format!("{:.1},{:.1}", sx(p.0), sy(p.1)))
            .collect();
        let _ = write!(
            s,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{c}\"/>\
             <text x=\"{}\" y=\"{}\" fill=\"{c}\">{}</text>",
            pts.join(" "),
            w - m + 4.0 - 160.0,
            m + 14.0 + 14.0 * fi as f64,
            esc(fam)
        );
        for (i, (r, p)) in rows.iter().zip(&pos).enumerate() {
            if r.family == *fam {
                let _ = write!(
                    s,
                    "<circle class=\"pt\" data-rung=\"{i}\" cx=\"{:.1}\" cy=\"{:.1}\" r=\"5\" \
                     fill=\"{c}\"><title>{} {}: {:.3} s, RMSE {:.4}</title></circle>",
                    sx(p.0),
                    sy(p.1),
                    esc(&r.family),
                    esc(&r.label),
                    r.seconds,
                    r.rmse
                );
            }
        }
    }
    s.push_str("</svg>");
    s
}

const STYLE: &str = "body{font-family:sans-serif;margin:1.5em;max-width:1200px}\
table{border-collapse:collapse}td,th{padding:3px 8px;border-bottom:1px solid #ddd;text-align:right}\
td:first-child,th:first-child,td:nth-child(2){text-align:left}tr.sel{background:#fe9}\
.compare{position:relative;display:inline-block;line-height:0}\
.compare img{image-rendering:pixelated;width:540px}\
#top{position:absolute;left:0;top:0;clip-path:inset(0 50% 0 0)}\
.maps{display:flex;flex-wrap:wrap;gap:16px}.maps figure{margin:0}.maps img{image-rendering:pixelated;width:360px}\
.bar{display:flex;align-items:center;gap:6px;font-size:12px}.bar img{height:12px}\
.pt{cursor:pointer}.note{color:#a40}\
.fireflies{display:flex;gap:16px;align-items:flex-start}.ffimg{position:relative;line-height:0}\
.ffimg img{image-rendering:pixelated;width:540px}\
#ffmarks{position:absolute;left:0;top:0;width:100%;height:100%}\
.ff{fill:none;stroke:#0ff;stroke-width:0.6}";

const SCRIPT: &str = r#"
const rungs = JSON.parse(document.getElementById('data').textContent);
function show(i) {
  const r = rungs[i];
  document.getElementById('top').src = r.image;
  document.getElementById('relmap').src = r.relmap;
  document.getElementById('flipmap').src = r.flipmap;
  document.getElementById('rungname').textContent = r.family + ' ' + r.label;
  for (const m of ['timemap', 'errmap']) document.getElementById(m).src = r[m];
  // A rung of one seed at 1 spp has no variance to measure: say so instead of a map.
  const product = document.getElementById('productmap');
  product.style.display = r.productmap ? '' : 'none';
  if (r.productmap) product.src = r.productmap;
  document.getElementById('productnote').style.display = r.productmap ? 'none' : '';
  document.getElementById('timemax').textContent = r.timemax.toPrecision(3);
  document.getElementById('ffimage').src = r.image;
  const ns = 'http://www.w3.org/2000/svg';
  const marks = document.getElementById('ffmarks');
  marks.replaceChildren();
  const rows = [];
  r.fireflies.forEach((f, k) => {
    const c = document.createElementNS(ns, 'circle');
    c.setAttribute('cx', f.x + 0.5);
    c.setAttribute('cy', f.y + 0.5);
    c.setAttribute('r', 1.5);
    c.setAttribute('class', 'ff');
    const t = document.createElementNS(ns, 'title');
    t.textContent = '#' + (k + 1) + ': pixel ' + f.x + ',' + f.y + ' sample ' + f.sample;
    c.appendChild(t);
    marks.appendChild(c);
    const tr = document.createElement('tr');
    for (const v of [k + 1, f.x + ',' + f.y, f.sample, f.luminance.toPrecision(4),
                     f.excess.toPrecision(4), f.path]) {
      const td = document.createElement('td');
      td.textContent = v;
      tr.appendChild(td);
    }
    rows.push(tr);
  });
  document.getElementById('fftable').replaceChildren(...rows);
  document.querySelectorAll('#rows tr').forEach((tr, k) => tr.classList.toggle('sel', k === i));
}
const slider = document.getElementById('slider');
slider.addEventListener('input', () => {
  document.getElementById('top').style.clipPath = 'inset(0 ' + (100 - slider.value) + '% 0 0)';
});
document.querySelectorAll('.pt').forEach(p => p.addEventListener('click', () => show(+p.dataset.rung)));
document.querySelectorAll('#rows tr').forEach((tr, k) => tr.addEventListener('click', () => show(k)));
function equalError() {
  const e = parseFloat(document.getElementById('target').value);
  const fams = [...new Set(rungs.map(r => r.family))];
  const out = fams.map(f => {
    const pts = rungs.filter(r => r.family === f).sort((a, b) => a.seconds - b.seconds);
    let t = null;
    if (pts.length && pts[0].rmse <= e) t = pts[0].seconds;
    for (let k = 0; t === null && k + 1 < pts.length; k++) {
      const a = pts[k], b = pts[k + 1];
      if (a.rmse >= e && b.rmse <= e && a.rmse > b.rmse) {
        const s = (Math.log(e) - Math.log(a.rmse)) / (Math.log(b.rmse) - Math.log(a.rmse));
        t = Math.exp(Math.log(a.seconds) + s * (Math.log(b.seconds) - Math.log(a.seconds)));
      }
    }
    return '<tr><td>' + f + '</td><td>' + (t === null ? 'not reached' : t.toFixed(3) + ' s') + '</td></tr>';
  });
  document.getElementById('equal').innerHTML = out.join('');
}
document.getElementById('target').addEventListener('input', equalError);
equalError();
show(0);
"#;

/// A path in a few words: the kinds of the surfaces it met, in order, and how it ended
/// (`Phong > Transmissive > Transmissive > escaped`).
fn path_summary(events: &[Event]) -> String {
    let mut parts: Vec<String> = Vec::new();
    for e in events {
        match e {
            Event::Hit { kind, .. } => parts.push((*kind).to_string()),
            Event::Escape { .. } => parts.push("escaped".into()),
            _ => {}
        }
    }
    if parts.is_empty() {
        "(not recorded: a shader other than Path)".into()
    } else {
        parts.join(" > ")
    }
}

/// The report as one HTML page.
pub fn html(r: &Report) -> String {
    let (w, h) = (r.reference.width, r.reference.height);
    let reference_png = png_uri(&to_rgb8(r.reference, r.transfer));
    // One heatmap scale for every rung, so rungs compare: the median of their 99th
    // percentiles (the worst rungs saturate, the best stay visible).
    let rel_maps: Vec<Vec<f32>> = r
        .rungs
        .iter()
        .map(|m| rel_se_map(&m.image, r.reference))
        .collect();
    let p99 = |v: &[f32]| {
        let mut s = v.to_vec();
        s.sort_by(f32::total_cmp);
        s.get(s.len() * 99 / 100).copied().unwrap_or(0.0)
    };
    let rel_max = {
        let mut p: Vec<f32> = rel_maps.iter().map(|m| p99(m)).collect();
        p.sort_by(f32::total_cmp);
        p.get(p.len() / 2).copied().unwrap_or(1.0).max(1e-6)
    };
    // Where the time goes: time per pixel (microseconds), squared error per pixel, and
    // variance times time, error and product each on one scale for every rung (the median of
    // their 99th percentiles).
    let time_maps: Vec<Vec<f32>> = r
        .rungs
        .iter()
        .map(|m| m.pixel_seconds.iter().map(|t| t * 1e6).collect())
        .collect();
    let err_maps: Vec<Vec<f32>> = r
        .rungs
        .iter()
        .map(|m| se_map(&m.image, r.reference))
        .collect();
    let product_maps: Vec<Option<Vec<f32>>> = time_maps
        .iter()
        .zip(r.rungs)
        .map(|(t, m)| {
            let v = m.pixel_variance.as_ref()?;
            Some(t.iter().zip(v).map(|(t, v)| t * v).collect())
        })
        .collect();
    let scale = |maps: &[Vec<f32>]| {
        let mut p: Vec<f32> = maps.iter().map(|m| p99(m)).collect();
        p.sort_by(f32::total_cmp);
        p.get(p.len() / 2).copied().unwrap_or(1.0).max(1e-12)
    };
    // Time on each rung's own scale (rungs differ in time by their spp; where it goes is the
    // question), error and product on one scale for all.
    // The product's scale over the rungs where it is known and not zero (a deterministic
    // rung has no variance).
    let known: Vec<Vec<f32>> = product_maps
        .iter()
        .flatten()
        .filter(|m| p99(m) > 0.0)
        .cloned()
        .collect();
    let (err_max, product_max) = (scale(&err_maps), scale(&known));
    let mut data = Vec::new();
    for (k, (m, rel)) in r.rungs.iter().zip(&rel_maps).enumerate() {
        let f = flip(&m.image, r.reference);
        let fireflies: Vec<serde_json::Value> = m
            .fireflies
            .iter()
            .map(|f| {
                serde_json::json!({
                    "x": f.pixel[0], "y": f.pixel[1], "sample": f.sample,
                    "luminance": f.luminance, "excess": f.excess,
                    "path": path_summary(&f.path),
                })
            })
            .collect();
        data.push(serde_json::json!({
            "family": m.row.family, "label": m.row.label, "seconds": m.row.seconds,
            "rmse": m.row.rmse,
            "image": png_uri(&to_rgb8(&m.image, r.transfer)),
            "relmap": png_uri(&magma(rel, w, h, rel_max)),
            "flipmap": png_uri(&f.heatmap),
            "timemap": png_uri(&magma(&time_maps[k], w, h, p99(&time_maps[k]).max(1e-12))),
            "timemax": p99(&time_maps[k]),
            "errmap": png_uri(&magma(&err_maps[k], w, h, err_max)),
            "productmap": product_maps[k]
                .as_ref()
                .map(|p| png_uri(&magma(p, w, h, product_max))),
            "fireflies": fireflies,
        }));
    }
    let rows: Vec<&Row> = r.rungs.iter().map(|m| &m.row).collect();
    let median_rmse = {
        let mut e: Vec<f64> = rows.iter().map(|r| r.rmse).collect();
        e.sort_by(f64::total_cmp);
        e.get(e.len() / 2).copied().unwrap_or(0.01)
    };
    let mut s = format!(
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>{t}</title>\
         <style>{STYLE}</style></head><body><h1>{t}</h1><p>Reference: {note}</p>",
        t = esc(&r.title),
        note = r.reference_note
    );
    let _ = write!(
        s,
        "<h2>Rung against reference: <span id=\"rungname\"></span></h2>\
         <p>Drag the slider: the rung on the left, the reference on the right. Click a point of \
         the plot or a row of the table to choose the rung.</p>\
         <div class=\"compare\"><img id=\"bottom\" src=\"{reference_png}\" alt=\"reference\">\
         <img id=\"top\" alt=\"rung\"></div><br>\
         <input id=\"slider\" type=\"range\" min=\"0\" max=\"100\" value=\"50\" style=\"width:540px\">\
         <h2>Where the error is</h2><div class=\"maps\">\
         <figure><img id=\"relmap\" alt=\"relative squared error\"><figcaption>relative squared \
         error (x - r)^2 / (r^2 + 0.01)</figcaption>{}</figure>\
         <figure><img id=\"flipmap\" alt=\"FLIP\"><figcaption>FLIP (perceived difference)\
         </figcaption>{}</figure></div>",
        colour_bar(rel_max, "(median 99th percentile)"),
        colour_bar(1.0, "")
    );
    let _ = write!(
        s,
        "<h2>Where the time goes</h2><p>The rung's time per pixel, its squared error per pixel \
         against the reference, and its variance per pixel times its time per pixel (the \
         inverse of the efficiency, lower is better; the variance across the seeds, or with \
         one seed the variance of the pixel's estimate from its samples). A rung that spends \
         its time where the error is not shows it at a glance: bright time where the error is \
         dark. Time from an inspected render of the same image (as <code>rtis render \
         --aov</code> measures it, but without counting BVH tests).</p><div class=\"maps\">\
         <figure><img id=\"timemap\" alt=\"time per pixel\"><figcaption>time per pixel\
         </figcaption>{}</figure>\
         <figure><img id=\"errmap\" alt=\"squared error per pixel\"><figcaption>squared error \
         (x - r)^2</figcaption>{}</figure>\
         <figure><img id=\"productmap\" alt=\"variance times time\"><p id=\"productnote\" \
         class=\"note\" style=\"display:none\">unknown: one image of 1 spp has no spread to \
         measure (run with --seeds 2 or more)</p><figcaption>variance &times; time\
         </figcaption>{}</figure></div>\
         <h2>Fireflies</h2><p>The rung's {REPORT_FIREFLIES} samples that stand out most above \
         the reference's pixel (by luminance), circled on its image, with the path that made \
         each (<code>rtis render --fireflies N</code> writes them with every vertex; \
         <code>rtis replay</code> retraces one).</p><div class=\"fireflies\"><div \
         class=\"ffimg\"><img id=\"ffimage\" alt=\"rung with its fireflies\"><svg \
         id=\"ffmarks\" viewBox=\"0 0 {w} {h}\" preserveAspectRatio=\"none\"></svg></div>\
         <table><thead><tr><th>#</th><th>pixel</th><th>sample</th><th>luminance</th>\
         <th>above the reference</th><th>path</th></tr></thead><tbody id=\"fftable\">\
         </tbody></table></div>",
        colour_bar_labelled("timemax", "&micro;s (the rung's 99th percentile)"),
        colour_bar(err_max, "(median 99th percentile)"),
        colour_bar(
            product_max,
            "&micro;s &times; variance (median 99th percentile)"
        ),
    );
    let _ = write!(
        s,
        "<h2>Error against time</h2>{}<h2>Every rung</h2><table><thead><tr><th>family</th>\
         <th>setting</th><th>seconds</th><th>Mrays</th><th>RMSE</th><th>relMSE</th>\
         <th>FLIP</th><th>bias&sup2;</th><th>variance</th></tr></thead><tbody id=\"rows\">",
        plot_svg(&rows)
    );
    for row in &rows {
        let _ = write!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{:.3}</td><td>{:.1}</td><td>{:.4}</td><td>{:.4}</td>\
             <td>{:.4}</td><td>{:.2e}</td><td>{:.2e}</td></tr>",
            esc(&row.family),
            esc(&row.label),
            row.seconds,
            row.rays as f64 / 1e6,
            row.rmse,
            row.rel_mse,
            row.flip,
            row.bias2,
            row.variance
        );
    }
    let seeds = rows.first().map_or(1, |r| r.seeds);
    let _ = write!(
        s,
        "</tbody></table><p>RMSE over {seeds} independent seeds; variance: the mean per-pixel \
         variance across them; bias&sup2;: the squared error of their mean less variance/{seeds} \
         and less the reference's noise (an unbiased estimate, so it can dip below zero where \
         the bias is small). A biased shader's error stops at its bias; an unbiased one's \
         falls as 1/spp.</p>\
         <h2>Equal error</h2><p>Time each family needs to reach RMSE \
         <input id=\"target\" type=\"number\" step=\"any\" value=\"{median_rmse:.4}\"> \
         (log-log interpolation between its rungs):</p><table><tbody id=\"equal\"></tbody></table>"
    );
    if !r.effects.is_empty() {
        let base = r.effects[0].seconds;
        s.push_str(
            "<h2>The price of each effect</h2><p>The scene's own shader with each effect it \
             needs switched off in turn: the time saved and the error it costs.</p><table>\
             <tr><th>effect off</th><th>seconds</th><th>speed-up</th><th>Mrays</th>\
             <th>RMSE</th><th>FLIP</th></tr>",
        );
        for e in r.effects {
            let _ = write!(
                s,
                "<tr><td>{}</td><td>{:.3}</td><td>{:.2}x</td><td>{:.1}</td><td>{:.4}</td>\
                 <td>{:.4}</td></tr>",
                if e.effect.is_empty() {
                    "none"
                } else {
                    &e.effect
                },
                e.seconds,
                base / e.seconds.max(1e-9),
                e.rays as f64 / 1e6,
                e.rmse,
                e.flip
            );
        }
        s.push_str("</table>");
    }
    let _ = writeln!(
        s,
        "<script id=\"data\" type=\"application/json\">{}</script><script>{SCRIPT}</script>\
         </body></html>",
        serde_json::Value::Array(data)
            .to_string()
            .replace("</", "<\\/")
    );
    s
}
