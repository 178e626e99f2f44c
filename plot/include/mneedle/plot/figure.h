#pragma once
// Figures as SVG files, drawn by PLplot (its svg driver): force against depth with markers for the
// stages and the puncture, several curves with a legend, axes with units. Values arrive in SI and
// each axis picks a readable unit by magnitude (um / mm / m, uN / mN / N, ...). docs/cli.md,
// "Plots".

#include <filesystem>
#include <string>
#include <vector>

#include "mneedle/base/units.h"

namespace mneedle::plot {

enum class Mark {
  Line,  ///< a polyline through the points
  Dots,  ///< a small circle at every point (measured samples)
};

/// One curve of a figure. x and y in SI of the figure's axes.
struct Series {
  std::string label;  ///< legend text ("" keeps it out of the legend)
  std::vector<double> x, y;
  Mark mark = Mark::Line;
};

/// A marked point (the puncture, the peak): a symbol and a label beside it.
struct Point {
  std::string label;
  double x = 0.0, y = 0.0;
};

/// A dashed vertical line across the plot with a label at its top (a stage boundary).
struct VerticalLine {
  std::string label;
  double x = 0.0;
};

struct Axis {
  std::string name;                         ///< "depth below the surface"
  Dimension dimension = Dimension::Length;  ///< picks the unit; Dimensionless prints `unit`
  std::string unit;                         ///< for Dimensionless axes only ("%", "")
  bool logarithmic = false;                 ///< every value must then be > 0
};

struct Figure {
  std::string title;
  Axis x{"depth", Dimension::Length, "", false};
  Axis y{"force", Dimension::Force, "", false};
  std::vector<Series> series;
  std::vector<Point> points;
  std::vector<VerticalLine> lines;
};

/// Writes the figure (a legend when it has two curves or more; through a temporary file in the same
/// folder, renamed at the end, so a failed run leaves no half-written file). Throws InputError
/// naming the file when it cannot be written, and naming the series when its x and y differ in
/// length, it has no finite point, or a logarithmic axis meets a value <= 0. Non-finite points are
/// left out of the lines. Safe to call from several threads (PLplot's state is global: calls are
/// serialised).
void write_svg(const std::filesystem::path& file, const Figure& figure);

/// The same figure as SVG text for embedding in a page: the <svg> element alone (no XML prolog
/// or DOCTYPE), drawn through a private temporary file; its ids (PLplot's clip paths) are unique to
/// the call, so several figures can share a page. Throws as write_svg.
std::string svg_element(const Figure& figure);

/// The unit an axis of this dimension shows for values up to `largest_abs` (SI), and its size
/// in SI: Length 1e-3 m -> ("mm", 1e-3). Used by write_svg; exposed for tests and tables.
struct DisplayUnit {
  std::string name;
  double si_per_unit = 1.0;
};
DisplayUnit display_unit(Dimension dimension, double largest_abs);

}  // namespace mneedle::plot
