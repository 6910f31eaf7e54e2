//! The SVG plot of GPU time against error: every measured setting as a dot
//! coloured by shader, the Pareto front as a staircase with its settings
//! labelled. Written by hand: a plotting crate would bring a dependency
//! tree for one scatter plot with two log axes.

use super::Report;
use std::fmt::Write;

const WIDTH: f64 = 860.0;
const HEIGHT: f64 = 560.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 230.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 60.0;
// Twelve colours that stay apart: one per reference shader.
const PALETTE: [&str; 12] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf",
    "#bcbd22", "#7f7f7f", "#000080", "#00a000",
];

/// Text safe inside an XML element or attribute.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A log10 axis from the 1-2-5 step at or below the smallest value to the
/// one at or above the largest (`lo`, `hi` are their logarithms).
struct Axis {
    lo: f64,
    hi: f64,
    from: f64,
    to: f64,
}

/// 1, 2 and 5 times each power of ten from 10^`a` to 10^`b`.
fn steps(a: i32, b: i32) -> impl Iterator<Item = f64> {
    (a..=b).flat_map(|e| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(e)))
}

impl Axis {
    fn new(values: impl Iterator<Item = f64>, from: f64, to: f64) -> Axis {
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for v in values.filter(|v| v.is_finite() && *v > 0.0) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if !lo.is_finite() {
            (lo, hi) = (1.0, 10.0);
        }
        let (a, b) = (lo.log10().floor() as i32 - 1, hi.log10().ceil() as i32);
        // A hair of slack, so a value on a step is not pushed past it.
        let low = steps(a, b)
            .filter(|&v| v <= lo * (1.0 + 1e-9))
            .last()
            .unwrap_or(lo);
        let high = steps(a, b).find(|&v| v >= hi * (1.0 - 1e-9)).unwrap_or(hi);
        let high = if high > low { high } else { low * 2.0 };
        Axis {
            lo: low.log10(),
            hi: high.log10(),
            from,
            to,
        }
    }

    fn map(&self, v: f64) -> f64 {
        let l = v.max(10f64.powf(self.lo)).log10();
        self.from + (l - self.lo) / (self.hi - self.lo) * (self.to - self.from)
    }

    /// Tick values: the 1-2-5 steps in range.
    fn ticks(&self) -> Vec<f64> {
        steps(self.lo.floor() as i32, self.hi.ceil() as i32)
            .filter(|v| (self.lo - 1e-9..=self.hi + 1e-9).contains(&v.log10()))
            .collect()
    }
}

/// Label heights near `wanted`, at least `gap` apart, within `[top,
/// bottom]` as far as they fit.
fn spread(wanted: &[f64], gap: f64, top: f64, bottom: f64) -> Vec<f64> {
    let mut order: Vec<usize> = (0..wanted.len()).collect();
    order.sort_by(|&a, &b| wanted[a].total_cmp(&wanted[b]));
    let mut y: Vec<f64> = order.iter().map(|&i| wanted[i]).collect();
    for k in 1..y.len() {
        y[k] = y[k].max(y[k - 1] + gap);
    }
    // Pushed past the bottom: move up from there.
    if let Some(last) = y.last_mut() {
        *last = last.min(bottom);
    }
    for k in (0..y.len().saturating_sub(1)).rev() {
        y[k] = y[k].min(y[k + 1] - gap);
    }
    if let Some(first) = y.first_mut() {
        *first = first.max(top);
    }
    let mut out = vec![0.0; wanted.len()];
    for (k, &i) in order.iter().enumerate() {
        out[i] = y[k];
    }
    out
}

fn label(v: f64) -> String {
    if v >= 1.0 {
        format!("{v:.0}")
    } else {
        let digits = (-v.log10().floor()) as usize;
        format!("{v:.digits$}")
    }
}

/// The plot of `report`'s measured settings.
pub fn svg(report: &Report) -> String {
    let points: Vec<(usize, f64, f64)> = report
        .rows
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            let m = r.measured()?;
            (m.gpu_ms > 0.0 && m.error.rmse > 0.0).then_some((i, m.gpu_ms, m.error.rmse))
        })
        .collect();
    let x = Axis::new(points.iter().map(|p| p.1), LEFT, WIDTH - RIGHT);
    let y = Axis::new(points.iter().map(|p| p.2), HEIGHT - BOTTOM, TOP);
    let mut shaders: Vec<&str> = Vec::new();
    for r in &report.rows {
        if !shaders.contains(&r.setting.shader.as_str()) {
            shaders.push(&r.setting.shader);
        }
    }
    let colour = |shader: &str| {
        let i = shaders.iter().position(|s| *s == shader).unwrap_or(0);
        PALETTE[i % PALETTE.len()]
    };
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(
        s,
        r#"<rect width="{WIDTH}" height="{HEIGHT}" fill="white"/>"#
    );
    let _ = writeln!(
        s,
        r#"<text x="{LEFT}" y="22" font-size="14">{}</text>"#,
        escape(&format!(
            "rtlint tradeoff: {} on `{}` ({}×{})",
            report.device.as_deref().unwrap_or("no device"),
            report.scene,
            report.sweep.width,
            report.sweep.height
        ))
    );
    // Grid and ticks.
    for t in x.ticks() {
        let px = x.map(t);
        let _ = writeln!(
            s,
            r##"<line x1="{px:.1}" y1="{TOP}" x2="{px:.1}" y2="{:.1}" stroke="#e0e0e0"/><text x="{px:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
            HEIGHT - BOTTOM,
            HEIGHT - BOTTOM + 16.0,
            label(t)
        );
    }
    for t in y.ticks() {
        let py = y.map(t);
        let _ = writeln!(
            s,
            r##"<line x1="{LEFT}" y1="{py:.1}" x2="{:.1}" y2="{py:.1}" stroke="#e0e0e0"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
            WIDTH - RIGHT,
            LEFT - 6.0,
            py + 4.0,
            label(t)
        );
    }
    let _ = writeln!(
        s,
        r#"<rect x="{LEFT}" y="{TOP}" width="{:.1}" height="{:.1}" fill="none" stroke="black"/>"#,
        WIDTH - RIGHT - LEFT,
        HEIGHT - BOTTOM - TOP
    );
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">GPU time per dispatch, ms (median of timestamp queries, log scale)</text>"#,
        (LEFT + WIDTH - RIGHT) / 2.0,
        HEIGHT - 18.0
    );
    let _ = writeln!(
        s,
        r#"<text transform="translate(18 {:.1}) rotate(-90)" text-anchor="middle">RMSE against the converged reference (log scale)</text>"#,
        (TOP + HEIGHT - BOTTOM) / 2.0
    );
    // The front as a staircase, fastest first.
    let mut front: Vec<&(usize, f64, f64)> =
        points.iter().filter(|p| report.rows[p.0].front).collect();
    front.sort_by(|a, b| a.1.total_cmp(&b.1));
    if !front.is_empty() {
        let mut path = String::new();
        for (k, p) in front.iter().enumerate() {
            let (px, py) = (x.map(p.1), y.map(p.2));
            if k == 0 {
                let _ = write!(path, "M{px:.1},{py:.1}");
            } else {
                let _ = write!(path, " H{px:.1} V{py:.1}");
            }
        }
        let _ = writeln!(
            s,
            r#"<path d="{path}" fill="none" stroke="black" stroke-width="1.5" stroke-dasharray="4 3"/>"#
        );
    }
    for &(i, t, e) in &points {
        let r = &report.rows[i];
        let (px, py) = (x.map(t), y.map(e));
        let title = escape(&format!("{}: {t:.4} ms, RMSE {e:.5}", r.setting.name()));
        if r.front {
            let _ = writeln!(
                s,
                r#"<circle cx="{px:.1}" cy="{py:.1}" r="5.5" fill="{}" stroke="black" stroke-width="1.5"><title>{title}</title></circle>"#,
                colour(&r.setting.shader)
            );
        } else {
            let _ = writeln!(
                s,
                r#"<circle cx="{px:.1}" cy="{py:.1}" r="3.5" fill="{}" fill-opacity="0.6"><title>{title}</title></circle>"#,
                colour(&r.setting.shader)
            );
        }
    }
    // Labels of the front, spread apart vertically inside the plot, with a
    // leader line where a label had to move.
    let wanted: Vec<f64> = front.iter().map(|p| y.map(p.2)).collect();
    let placed = spread(&wanted, 12.0, TOP + 8.0, HEIGHT - BOTTOM - 4.0);
    for (p, ly) in front.iter().zip(placed) {
        let (px, py) = (x.map(p.1), y.map(p.2));
        let right_third = px > LEFT + (WIDTH - RIGHT - LEFT) * 2.0 / 3.0;
        let dx = if right_third { -7.0 } else { 7.0 };
        if (ly - py).abs() > 2.0 {
            let _ = writeln!(
                s,
                r##"<line x1="{px:.1}" y1="{py:.1}" x2="{:.1}" y2="{ly:.1}" stroke="#808080" stroke-width="0.7"/>"##,
                px + dx
            );
        }
        // Right of the point, or left of it in the plot's right third, so
        // the text stays off the legend.
        let (tx, anchor) = if right_third {
            (px - 8.0, "end")
        } else {
            (px + 8.0, "start")
        };
        let _ = writeln!(
            s,
            r#"<text x="{tx:.1}" y="{:.1}" text-anchor="{anchor}">{}</text>"#,
            ly + 4.0,
            escape(&report.rows[p.0].setting.name())
        );
    }
    // Legend.
    let lx = WIDTH - RIGHT + 20.0;
    let _ = writeln!(
        s,
        r#"<text x="{lx:.1}" y="{:.1}" font-weight="bold">shader</text>"#,
        TOP + 10.0
    );
    for (k, sh) in shaders.iter().enumerate() {
        let ly = TOP + 28.0 + 16.0 * k as f64;
        let _ = writeln!(
            s,
            r#"<circle cx="{:.1}" cy="{:.1}" r="4" fill="{}"/><text x="{:.1}" y="{:.1}">{}</text>"#,
            lx + 4.0,
            ly - 4.0,
            colour(sh),
            lx + 14.0,
            ly,
            escape(sh)
        );
    }
    let ly = TOP + 28.0 + 16.0 * shaders.len() as f64 + 10.0;
    let _ = writeln!(
        s,
        r#"<circle cx="{:.1}" cy="{:.1}" r="5.5" fill="white" stroke="black" stroke-width="1.5"/><text x="{:.1}" y="{ly:.1}">on the Pareto front</text>"#,
        lx + 4.0,
        ly - 4.0,
        lx + 14.0
    );
    s.push_str("</svg>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_cover_the_values_and_text_is_escaped() {
        let a = Axis::new([0.03, 4.0].into_iter(), 0.0, 100.0);
        // From the step 0.02 to the step 5.
        assert!((a.lo - 0.02f64.log10()).abs() < 1e-12, "{}", a.lo);
        assert!((a.hi - 5f64.log10()).abs() < 1e-12, "{}", a.hi);
        assert!(a.map(0.03) > 0.0 && a.map(4.0) < 100.0);
        assert_eq!(a.map(0.01), 0.0);
        let ticks: Vec<String> = a.ticks().into_iter().map(label).collect();
        assert_eq!(ticks, ["0.02", "0.05", "0.1", "0.2", "0.5", "1", "2", "5"]);
        // Values on a step stay on it.
        let b = Axis::new([1.0, 10.0].into_iter(), 0.0, 1.0);
        assert!(b.map(1.0).abs() < 1e-9 && (b.map(10.0) - 1.0).abs() < 1e-9);
        assert_eq!(escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
        assert_eq!(label(0.02), "0.02");
        assert_eq!(label(50.0), "50");
    }

    #[test]
    fn labels_spread_apart_and_stay_inside() {
        let y = spread(&[100.0, 101.0, 99.0, 300.0], 12.0, 0.0, 400.0);
        let mut sorted = y.clone();
        sorted.sort_by(f64::total_cmp);
        assert!(
            sorted.windows(2).all(|w| w[1] - w[0] >= 12.0 - 1e-9),
            "{y:?}"
        );
        assert_eq!(y[3], 300.0, "a label with room keeps its place");
        // Crowded at the bottom: pushed up, not out.
        let y = spread(&[395.0, 396.0, 397.0], 12.0, 0.0, 400.0);
        assert!(y.iter().all(|&v| v <= 400.0), "{y:?}");
    }
}
