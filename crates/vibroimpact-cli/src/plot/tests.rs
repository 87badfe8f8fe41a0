//! Tests of figure rendering.
use super::axis::*;
use super::figure::*;
use super::layout::*;
use super::raster::*;
use super::theme::*;
use super::*;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "vibroimpact-plot-{name}-{}-{:?}",
        std::process::id(),
        std::thread::current().id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn sample_figure() -> Figure {
    let curve: Vec<(f64, f64)> = (0..=100)
        .map(|i| {
            let v = 10f64.powf(-3.0 + 5.0 * f64::from(i) / 100.0);
            (v, 0.9 - 0.3 * (1.0 + v.ln() / 5.0).tanh())
        })
        .collect();
    let scatter: Vec<(f64, f64)> = curve
        .iter()
        .step_by(10)
        .map(|&(v, e)| (v, e + 0.02))
        .collect();
    let reference: Vec<(f64, f64)> = curve.iter().map(|&(v, _)| (v, 0.75)).collect();
    Figure::new(
        "Restitution vs impact velocity",
        "impact velocity V [m/s]",
        "e",
    )
    .log_x()
    .with_series(Series::line("model", curve))
    .with_series(Series::markers("simulation", scatter, Marker::Circle))
    .with_series(Series::dashed("reference", reference))
}

fn assert_png(path: &Path) {
    let bytes = std::fs::read(path).unwrap();
    assert!(
        bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
        "not a PNG: {path:?}"
    );
    assert!(
        bytes.len() > 10_000,
        "suspiciously small PNG: {}",
        bytes.len()
    );
    // IHDR: width and height.
    assert_eq!(&bytes[12..16], b"IHDR");
    assert_eq!(u32::from_be_bytes(bytes[16..20].try_into().unwrap()), PNG_W);
    assert_eq!(u32::from_be_bytes(bytes[20..24].try_into().unwrap()), PNG_H);
}

fn no_temp_files(dir: &Path) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.contains(".tmp"), "temporary file left: {name}");
    }
}

#[test]
fn renders_svg_and_png() {
    let dir = temp_dir("basic");
    let stem = dir.join("fig_restitution");
    render(&sample_figure(), &stem).unwrap();
    let svg = std::fs::read_to_string(dir.join("fig_restitution.svg")).unwrap();
    assert!(svg.starts_with("<svg"));
    assert!(svg.contains("Restitution vs impact velocity"));
    for label in [
        "model",
        "simulation",
        "reference",
        "impact velocity V [m/s]",
    ] {
        assert!(svg.contains(label), "missing {label}");
    }
    assert!(svg.contains("font-family=\"DejaVu Sans, sans-serif\""));
    assert!(svg.contains("width=\"900\" height=\"600\""));
    // Decade labels on the log axis.
    assert!(svg.contains("10\u{207B}\u{00B3}") && svg.contains("10\u{00B2}"));
    assert_png(&dir.join("fig_restitution.png"));
    no_temp_files(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn png_text_is_rendered() {
    // Same figure with and without text: the text must change the pixels.
    // Dark pixels above the plot area: only the title can be there.
    let dark_above_plot = |fig: &Figure| {
        assert!(ensure_font());
        let plan = Plan::new(fig).unwrap();
        let pixels = render_png_pixels(fig, &plan).unwrap();
        let rows = ((plan.top - TICK_EM) * f64::from(PNG_H) / H) as usize;
        pixels[..PNG_W as usize * 3 * rows]
            .iter()
            .filter(|&&v| v < 128)
            .count()
    };
    let titled = Figure::new("TITLE", "", "").legend_at(LegendPosition::None);
    let blank = Figure::new("", "", "").legend_at(LegendPosition::None);
    let n = dark_above_plot(&titled);
    assert!(n > 300, "title not drawn: {n} dark pixels");
    assert_eq!(dark_above_plot(&blank), 0);
}

#[test]
fn deterministic() {
    let dir = temp_dir("det");
    let fig = sample_figure().log_y();
    render(&fig, &dir.join("a")).unwrap();
    render(&fig, &dir.join("b")).unwrap();
    for ext in ["svg", "png"] {
        let a = std::fs::read(dir.join(format!("a.{ext}"))).unwrap();
        let b = std::fs::read(dir.join(format!("b.{ext}"))).unwrap();
        assert_eq!(a, b, "{ext} differs");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn edge_cases_do_not_panic() {
    let dir = temp_dir("edge");
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let figures = vec![
        Figure::new("empty", "x", "y"),
        Figure::new("empty series", "x", "y").with_series(Series::line("none", vec![])),
        Figure::new("single point", "x", "y").with_series(Series::line("one", vec![(1.0, 2.0)])),
        Figure::new("single marker", "x", "y")
            .log_x()
            .log_y()
            .with_series(Series::markers("one", vec![(3.0, 3.0)], Marker::Triangle)),
        Figure::new("constant", "x", "y")
            .with_series(Series::line("c", (0..10).map(|i| (f64::from(i), 5.0)))),
        Figure::new("zero constant", "x", "y")
            .with_series(Series::line("c", vec![(0.0, 0.0), (0.0, 0.0)])),
        Figure::new("nan and inf", "x", "y").with_series(Series::line(
            "bad",
            vec![
                (0.0, 1.0),
                (nan, 2.0),
                (1.0, inf),
                (2.0, 3.0),
                (3.0, -inf),
                (4.0, 2.0),
            ],
        )),
        Figure::new("all invalid on log", "x", "y")
            .log_x()
            .with_series(Series::line("neg", vec![(-1.0, 1.0), (0.0, 2.0)])),
        Figure::new("tiny numbers", "x", "y").with_series(Series::markers(
            "tiny",
            (1..20).map(|i| (f64::from(i) * 1e-7, f64::from(i) * 3e-9)),
            Marker::Square,
        )),
        Figure::new("huge numbers", "x", "y").with_series(Series::line(
            "huge",
            (1..20).map(|i| (f64::from(i) * 2.5e4, f64::from(i) * 1e12)),
        )),
        Figure::new("very wide log", "x", "y")
            .log_x()
            .log_y()
            .with_series(Series::line(
                "wide",
                (0..50).map(|i| (10f64.powi(i * 6 - 150), 10f64.powi(i - 25))),
            )),
        Figure::new("narrow log", "x", "y")
            .log_x()
            .log_y()
            .with_series(Series::line(
                "narrow",
                (0..20).map(|i| (1.0 + f64::from(i) * 1e-4, 2.0 + f64::from(i) * 1e-3)),
            )),
        Figure::new("nearly constant", "x", "y").with_series(Series::line(
            "n",
            (0..20).map(|i| (f64::from(i), 1e16 + f64::from(i))),
        )),
        Figure::new("outside explicit range", "x", "y")
            .x_range(0.0, 1.0)
            .y_range(0.0, 1.0)
            .with_series(Series::markers(
                "out",
                vec![
                    (-5.0, 0.5),
                    (0.5, 0.5),
                    (0.5, 9.0),
                    (1e300, -1e300),
                    (0.7, 0.2),
                ],
                Marker::Circle,
            )),
        Figure::new("extreme values", "x", "y").with_series(Series::line(
            "x",
            vec![
                (f64::MAX, 1.0),
                (-f64::MAX, -1.0),
                (0.0, 0.0),
                (1.0, f64::MIN_POSITIVE),
            ],
        )),
        Figure::new("", "", "")
            .legend_at(LegendPosition::LowerLeft)
            .with_series(Series::dashed("d", vec![(0.0, 0.0), (1.0, 1.0)]).with_color(17)),
    ];
    for (i, fig) in figures.iter().enumerate() {
        let stem = dir.join(format!("edge{i}"));
        render(fig, &stem).unwrap_or_else(|e| panic!("{}: {e}", fig.title));
        assert_png(&with_suffix(&stem, ".png"));
    }
    no_temp_files(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn invalid_explicit_range_is_an_error_naming_the_file() {
    let dir = temp_dir("invalid");
    let stem = dir.join("bad");
    let fig = Figure::new("t", "x", "y").log_x().x_range(0.0, 1.0);
    let err = render(&fig, &stem).unwrap_err();
    assert!(err.to_string().contains("bad.svg"), "{err}");
    let fig = Figure::new("t", "x", "y").y_range(2.0, 1.0);
    assert!(render(&fig, &stem).is_err());
    assert!(std::fs::read_dir(&dir).unwrap().next().is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn tick_labels_are_compact() {
    let (v, step) = nice_ticks(0.0, 1e-5, 6);
    let labels = format_linear(&v, step);
    assert_eq!(labels[0], "0");
    assert!(
        labels.contains(&"1\u{00D7}10\u{207B}\u{2075}".to_string()),
        "{labels:?}"
    );
    let (v, step) = nice_ticks(0.0, 1e5, 5);
    let labels = format_linear(&v, step);
    assert_eq!(labels, ["0", "5\u{00D7}10\u{2074}", "1\u{00D7}10\u{2075}"]);
    let labels = format_linear(&[1.5e7, 2.5e7], 5e6);
    assert_eq!(labels, ["1.5\u{00D7}10\u{2077}", "2.5\u{00D7}10\u{2077}"]);
    let (v, step) = nice_ticks(-1.0, 1.0, 5);
    assert_eq!(
        format_linear(&v, step),
        ["\u{2212}1.0", "\u{2212}0.5", "0", "0.5", "1.0"]
    );
    assert_eq!(decade_label(-3), "10\u{207B}\u{00B3}");
    assert_eq!(decade_label(10), "10\u{00B9}\u{2070}");
}

#[test]
fn log_axis_labels_do_not_overlap() {
    assert!(ensure_font());
    for (lo, hi) in [
        (-3.0, 2.0),
        (-30.0, 30.0),
        (0.1, 0.9),
        (0.0, 0.01),
        (-150.0, 150.0),
    ] {
        for length in [200.0, 700.0] {
            let plan = plan_axis(Scale::Log, lo, hi, length, false);
            assert!(plan.major.len() >= 2, "{lo}..{hi}: {:?}", plan.major);
            let pos: Vec<f64> = plan
                .major
                .iter()
                .map(|(t, _)| plan.frac(*t) * length)
                .collect();
            let size: Vec<f64> = plan
                .major
                .iter()
                .map(|(_, s)| text_width(s, TICK_EM))
                .collect();
            assert!(
                labels_fit(&pos, &size, 0.0),
                "{lo}..{hi} @ {length}: {:?}",
                plan.major
            );
        }
    }
}

#[test]
fn clipping_and_dashes() {
    let rect = (0.0, 0.0, 10.0, 10.0);
    let (a, b, ao, bo) = clip_segment((-5.0, 5.0), (5.0, 5.0), rect).unwrap();
    assert_eq!((a, b, ao, bo), ((0.0, 5.0), (5.0, 5.0), false, true));
    assert!(clip_segment((-5.0, -5.0), (-1.0, 20.0), rect).is_none());
    let d = dashes(&[(0.0, 0.0), (20.0, 0.0)], (4.0, 2.0));
    assert_eq!(d.len(), 4);
    assert_eq!(d[1], vec![(6.0, 0.0), (10.0, 0.0)]);
}

/// Pixels inside the plot area of `fig` (PNG) for which `pick` holds.
fn plot_pixels(fig: &Figure, pick: impl Fn(&[u8]) -> bool) -> usize {
    assert!(ensure_font());
    let plan = Plan::new(fig).unwrap();
    let pixels = render_png_pixels(fig, &plan).unwrap();
    let (sx, sy) = (f64::from(PNG_W) / W, f64::from(PNG_H) / H);
    let (x0, x1) = (
        (plan.left * sx) as usize + 4,
        (plan.right * sx) as usize - 4,
    );
    let (y0, y1) = (
        (plan.top * sy) as usize + 4,
        (plan.bottom * sy) as usize - 4,
    );
    let mut n = 0;
    for y in y0..y1 {
        for x in x0..x1 {
            let i = 3 * (y * PNG_W as usize + x);
            n += usize::from(pick(&pixels[i..i + 3]));
        }
    }
    n
}

#[test]
fn a_halo_keeps_a_black_line_visible_over_black_cells() {
    // A black cell over the whole plot with a black line across it: white
    // pixels appear only with the halo, as a band on either side of the line.
    let over_black = |halo: bool| {
        let line = Series::line("", vec![(0.0, 0.5), (1.0, 0.5)]).with_color(6);
        let line = if halo { line.with_halo() } else { line };
        let fig = Figure::new("", "", "")
            .legend_at(LegendPosition::None)
            .x_range(0.0, 1.0)
            .y_range(0.0, 1.0)
            .with_series(Series::rectangles("", vec![(-1.0, -1.0, 2.0, 2.0)]).with_color(6))
            .with_series(line);
        plot_pixels(&fig, |p| p.iter().all(|&v| v > 200))
    };
    assert_eq!(over_black(false), 0);
    let white = over_black(true);
    // Two bands of 1.5 logical px (2 PNG px each) along ~800 PNG px.
    assert!((2000..6000).contains(&white), "{white} white pixels");
}

#[test]
fn dots_are_small_markers() {
    // The same 50 points as circles and as dots: a dot inks under a fifth
    // of a circle (radius 1.3 against 4.5 logical px: 1/12 of the area,
    // 1/9.5 measured after supersampling).
    let inked = |marker: Marker| {
        let pts: Vec<(f64, f64)> = (0..50).map(|k| (k as f64, (k % 7) as f64)).collect();
        let fig = Figure::new("", "", "")
            .legend_at(LegendPosition::None)
            .with_series(Series::markers("", pts, marker));
        plot_pixels(&fig, |p| p.iter().any(|&v| v < 200))
    };
    let (circle, dot) = (inked(Marker::Circle), inked(Marker::Dot));
    assert!(dot > 0 && 5 * dot < circle, "dot {dot}, circle {circle}");
}

/// A chart's cells fill the plot area, so a legend inside covered some
/// (issue 38). Outside, the plot area narrows by the legend's width and
/// the legend sits right of it, inside the figure; tags are written as
/// text beside their points.
#[test]
fn an_outside_legend_covers_no_cell() {
    let cells: Vec<(f64, f64, f64, f64)> = (0..10)
        .flat_map(|i| {
            (0..10).map(move |j| {
                (
                    f64::from(i),
                    f64::from(j),
                    f64::from(i) + 1.0,
                    f64::from(j) + 1.0,
                )
            })
        })
        .collect();
    let inside =
        Figure::new("cells", "x", "y").with_series(Series::rectangles("period 1", cells.clone()));
    let fig = Figure::new("cells", "x", "y")
        .with_series(Series::rectangles("period 1", cells))
        .with_series(
            Series::markers("marked", [(2.5, 2.5)], Marker::Cross).with_tags(vec!["BP1".into()]),
        )
        .legend_at(LegendPosition::Outside);
    let (wide, plan) = (Plan::new(&inside).unwrap(), Plan::new(&fig).unwrap());
    let (w, h) = legend_size(&fig).unwrap();
    let (x0, y0) = super::draw::legend_origin(&plan, LegendPosition::Outside, w, h);
    assert!(
        x0 >= plan.right + LEGEND_GAP - 1e-9,
        "{x0} vs {}",
        plan.right
    );
    assert!(x0 + w <= W, "{} > {W}", x0 + w);
    assert!((y0 - plan.top).abs() < 1e-9);
    assert!(plan.right < wide.right - w);
    let dir = temp_dir("outside");
    render(&fig, &dir.join("f")).unwrap();
    let svg = std::fs::read_to_string(dir.join("f.svg")).unwrap();
    assert!(svg.contains("BP1"), "the tag is missing");
}
