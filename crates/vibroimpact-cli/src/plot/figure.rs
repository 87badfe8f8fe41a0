//! The figure description: series, axes, legend.

/// Axis scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scale {
    /// Linear axis.
    #[default]
    Linear,
    /// Base-10 logarithmic axis; non-positive values are not drawn.
    Log,
}

/// Marker shape for scatter points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// Filled circle.
    Circle,
    /// Filled square.
    Square,
    /// Filled upward triangle.
    Triangle,
    /// Filled diamond.
    Diamond,
    /// A diagonal cross (two strokes).
    Cross,
    /// A small filled circle, for dense scatter (an orbit diagram's
    /// thousands of samples).
    Dot,
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Solid line through the points.
    Line,
    /// Dashed line through the points.
    DashedLine,
    /// Markers only.
    Markers(Marker),
    /// Filled rectangles, one per pair of consecutive points (two opposite
    /// corners): the cells of a chart.
    Rectangles,
}

/// Where the legend box goes (inside the plot area).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LegendPosition {
    /// Upper left corner.
    UpperLeft,
    /// Upper right corner (default).
    #[default]
    UpperRight,
    /// Lower left corner.
    LowerLeft,
    /// Lower right corner.
    LowerRight,
    /// The corner where the legend box covers the least data.
    Best,
    /// Right of the plot area, which narrows to make room: for figures
    /// whose data fill the area (a chart's cells).
    Outside,
    /// No legend.
    None,
}

/// One data series of a figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text; `None` keeps the series out of the legend.
    pub label: Option<String>,
    /// Data points `(x, y)`. Points with a NaN or infinite coordinate, or a
    /// non-positive coordinate on a log axis, are skipped (a line is broken there).
    pub points: Vec<(f64, f64)>,
    /// How the series is drawn.
    pub style: Style,
    /// Palette index (wraps around); `None` takes the next unused palette colour.
    pub color: Option<usize>,
    /// Drawn over a light halo, so that it stays visible over filled cells
    /// of any colour.
    pub halo: bool,
    /// Text beside each point's marker, in the order of `points` (empty:
    /// none): the labels of a branch's special points.
    pub tags: Vec<String>,
}

impl Series {
    /// A series with the given style; an empty `label` means no legend entry.
    pub fn new(
        label: impl Into<String>,
        points: impl IntoIterator<Item = (f64, f64)>,
        style: Style,
    ) -> Self {
        let label = label.into();
        Self {
            label: (!label.is_empty()).then_some(label),
            points: points.into_iter().collect(),
            style,
            color: None,
            halo: false,
            tags: Vec::new(),
        }
    }

    /// A solid line; an empty `label` means no legend entry.
    pub fn line(label: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Self::new(label, points, Style::Line)
    }

    /// A dashed line; an empty `label` means no legend entry.
    pub fn dashed(label: impl Into<String>, points: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Self::new(label, points, Style::DashedLine)
    }

    /// Markers only (scatter); an empty `label` means no legend entry.
    pub fn markers(
        label: impl Into<String>,
        points: impl IntoIterator<Item = (f64, f64)>,
        marker: Marker,
    ) -> Self {
        Self::new(label, points, Style::Markers(marker))
    }

    /// Filled rectangles given by `(x0, y0, x1, y1)` corners; an empty
    /// `label` means no legend entry.
    pub fn rectangles(
        label: impl Into<String>,
        corners: impl IntoIterator<Item = (f64, f64, f64, f64)>,
    ) -> Self {
        let points = corners
            .into_iter()
            .flat_map(|(x0, y0, x1, y1)| [(x0, y0), (x1, y1)]);
        Self::new(label, points, Style::Rectangles)
    }

    /// Sets the palette index of the series colour.
    pub fn with_color(mut self, palette_index: usize) -> Self {
        self.color = Some(palette_index);
        self
    }

    /// Writes `tags` beside the points' markers, one per point in order.
    pub fn with_tags(mut self, tags: Vec<String>) -> Self {
        self.tags = tags;
        self
    }

    /// Draws the series over a light halo (lines and markers outlined in
    /// white), for series drawn over a chart's cells.
    pub fn with_halo(mut self) -> Self {
        self.halo = true;
        self
    }
}

/// Description of one figure: axes, series and legend.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Title above the plot (empty: none).
    pub title: String,
    /// Label of the horizontal axis (empty: none).
    pub x_label: String,
    /// Label of the vertical axis (empty: none).
    pub y_label: String,
    /// Scale of the horizontal axis.
    pub x_scale: Scale,
    /// Scale of the vertical axis.
    pub y_scale: Scale,
    /// Explicit x range `(min, max)`; `None`: from the data with a small margin.
    pub x_range: Option<(f64, f64)>,
    /// Explicit y range `(min, max)`; `None`: from the data with a small margin
    /// (only points inside an explicit x range are considered).
    pub y_range: Option<(f64, f64)>,
    /// The series, drawn in order.
    pub series: Vec<Series>,
    /// Legend placement.
    pub legend: LegendPosition,
}

impl Figure {
    /// A figure with linear axes, automatic ranges, no series and the legend upper right.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            x_range: None,
            y_range: None,
            series: Vec::new(),
            legend: LegendPosition::UpperRight,
        }
    }

    /// Makes the x axis logarithmic.
    pub fn log_x(mut self) -> Self {
        self.x_scale = Scale::Log;
        self
    }

    /// Makes the y axis logarithmic.
    pub fn log_y(mut self) -> Self {
        self.y_scale = Scale::Log;
        self
    }

    /// Fixes the x range.
    pub fn x_range(mut self, min: f64, max: f64) -> Self {
        self.x_range = Some((min, max));
        self
    }

    /// Fixes the y range.
    pub fn y_range(mut self, min: f64, max: f64) -> Self {
        self.y_range = Some((min, max));
        self
    }

    /// Sets the legend position.
    pub fn legend_at(mut self, position: LegendPosition) -> Self {
        self.legend = position;
        self
    }

    /// Adds a series (builder style).
    pub fn with_series(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Adds a series.
    pub fn push(&mut self, series: Series) -> &mut Self {
        self.series.push(series);
        self
    }
}
