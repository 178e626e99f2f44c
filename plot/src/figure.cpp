#include "mneedle/plot/figure.h"

#include <plplot/plplot.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>
#include <system_error>

#include <unistd.h>

#include "mneedle/base/error.h"

namespace mneedle::plot {
namespace {

// PLplot keeps its streams in global state: one figure at a time.
std::mutex plplot_mutex;

// Colour map 0: 0 background (white), 15 foreground (black), 14 grey for the stage lines, 1..10
// the curves (the Tableau 10 palette: distinguishable, and readable when printed grey).
constexpr int kPalette[10][3] = {{31, 119, 180},  {214, 39, 40}, {44, 160, 44},   {255, 127, 14},
                                 {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127},
                                 {188, 189, 34},  {23, 190, 207}};
constexpr int kForeground = 15, kGrey = 14;
// Legend lines that fit beside a rising curve in the top-left corner of the default figure.
constexpr std::size_t kMaxLegendEntries = 8;

// PLplot reads '#' as its escape character in text.
std::string escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    out += c;
    if (c == '#') out += '#';
  }
  return out;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return !(lo <= hi); }
};

std::string axis_label(const Axis& a, const DisplayUnit& u) {
  const std::string unit = a.dimension == Dimension::Dimensionless ? a.unit : u.name;
  return unit.empty() ? a.name : a.name + " [" + unit + "]";
}

// Converts to the axis's display unit (and to log10 on a logarithmic axis).
double to_axis(double si, const Axis& a, const DisplayUnit& u) {
  const double v = si / u.si_per_unit;
  return a.logarithmic ? std::log10(v) : v;
}

void check(const std::filesystem::path& file, const Figure& f) {
  for (const Series& s : f.series) {
    const std::string name = "'" + s.label + "'";
    if (s.x.size() != s.y.size())
      throw InputError(file.string() + ": plot series " + name + " has " +
                       std::to_string(s.x.size()) + " x values and " + std::to_string(s.y.size()) +
                       " y values");
    bool any = false;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      any = true;
      if ((f.x.logarithmic && !(s.x[i] > 0)) || (f.y.logarithmic && !(s.y[i] > 0)))
        throw InputError(file.string() + ": plot series " + name +
                         " has a value <= 0 on a logarithmic axis");
    }
    if (!any) throw InputError(file.string() + ": plot series " + name + " has no finite point");
  }
}

}  // namespace

DisplayUnit display_unit(Dimension d, double largest) {
  const auto pick = [&](std::initializer_list<DisplayUnit> units) {
    DisplayUnit chosen = *units.begin();
    for (const DisplayUnit& u : units)
      if (largest >= u.si_per_unit) chosen = u;
    return chosen;
  };
  switch (d) {
    case Dimension::Length:
      return pick({{"um", 1e-6}, {"mm", 1e-3}, {"m", 1.0}});
    case Dimension::Force:
      return pick({{"uN", 1e-6}, {"mN", 1e-3}, {"N", 1.0}});
    case Dimension::Pressure:
      return pick({{"Pa", 1.0}, {"kPa", 1e3}, {"MPa", 1e6}, {"GPa", 1e9}});
    case Dimension::Time:
      return pick({{"ms", 1e-3}, {"s", 1.0}});
    case Dimension::Energy:
      return pick({{"uJ", 1e-6}, {"mJ", 1e-3}, {"J", 1.0}});
    default:
      return {std::string(si_unit(d)), 1.0};
  }
}

void write_svg(const std::filesystem::path& file, const Figure& f) {
  check(file, f);
  Range xr, yr;
  for (const Series& s : f.series)
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        xr.add(s.x[i]);
        yr.add(s.y[i]);
      }
  for (const Point& p : f.points) {
    xr.add(p.x);
    yr.add(p.y);
  }
  if (xr.empty()) throw InputError(file.string() + ": plot has no data");
  const DisplayUnit ux = display_unit(f.x.dimension, std::max(std::abs(xr.lo), std::abs(xr.hi)));
  const DisplayUnit uy = display_unit(f.y.dimension, std::max(std::abs(yr.lo), std::abs(yr.hi)));
  double x0 = to_axis(xr.lo, f.x, ux), x1 = to_axis(xr.hi, f.x, ux);
  double y0 = to_axis(yr.lo, f.y, uy), y1 = to_axis(yr.hi, f.y, uy);
  // A force axis starts at zero unless the data go below it; a flat range gets a unit of room.
  if (!f.y.logarithmic) y0 = std::min(y0, 0.0);
  if (!f.x.logarithmic) x0 = std::min(x0, 0.0);  // depth from the surface or contact: from 0
  if (!(x1 > x0)) x1 = x0 + 1.0;
  if (!(y1 > y0)) y1 = y0 + 1.0;
  const double pad = 0.05 * (y1 - y0);
  y1 += pad;
  if (y0 < 0.0 || f.y.logarithmic) y0 -= pad;
  // A logarithmic x axis does not start at zero: room on both sides, so that the outermost
  // points are not cut in half by the frame.
  if (f.x.logarithmic) {
    const double room = 0.03 * (x1 - x0);
    x0 -= room;
    x1 += room;
  }
  // Headroom for the legend (top left, about 5.5 % of the height a line, 3 % of frame) so that
  // it sits above the data instead of on them.
  const auto labelled = static_cast<std::size_t>(std::count_if(
      f.series.begin(), f.series.end(), [](const Series& s) { return !s.label.empty(); }));
  // (On a logarithmic axis the same share of the height, in decades.)
  if (labelled > 1) {
    const double covered =
        0.03 + 0.055 * static_cast<double>(std::min(labelled, kMaxLegendEntries));
    y1 = y0 + (y1 - y0) / (1.0 - covered);
  }

  std::error_code ec;
  const auto tmp = std::filesystem::path(file.string() + ".tmp");
  {
    std::ofstream probe(tmp);  // PLplot exits the process when it cannot open its file
    if (!probe) throw InputError(file.string() + ": cannot write the plot");
  }

  std::lock_guard<std::mutex> lock(plplot_mutex);
  PLINT stream = 0;
  plmkstrm(&stream);
  plsdev("svg");
  plsfnam(tmp.c_str());
  plspage(0, 0, 800, 500, 0, 0);
  plscolbg(255, 255, 255);
  plscol0(kForeground, 0, 0, 0);
  plscol0(kGrey, 150, 150, 150);
  for (int k = 0; k < 10; ++k) plscol0(k + 1, kPalette[k][0], kPalette[k][1], kPalette[k][2]);
  plinit();
  plcol0(kForeground);
  const PLINT axis = (f.x.logarithmic ? 10 : 0) + (f.y.logarithmic ? 20 : 0);
  plenv(x0, x1, y0, y1, 0, axis);
  pllab(escaped(axis_label(f.x, ux)).c_str(), escaped(axis_label(f.y, uy)).c_str(),
        escaped(f.title).c_str());

  // Stage lines first, under the curves; their labels at three heights in turn, so that close
  // lines do not print over each other.
  int line_number = 0;
  for (const VerticalLine& v : f.lines) {
    const double x = to_axis(v.x, f.x, ux);
    if (!std::isfinite(x)) continue;
    plcol0(kGrey);
    pllsty(2);
    pljoin(x, y0, x, y1);
    pllsty(1);
    plschr(0, 0.7);
    // Labels along the bottom: force curves rise, so the top holds the data and the legend.
    const double height = 0.03 + 0.05 * (line_number++ % 3);
    plptex(x, y0 + height * (y1 - y0), 1.0, 0.0, -0.15, escaped(v.label).c_str());
    plschr(0, 1.0);
  }

  std::vector<PLINT> opt, text_colour, line_colour, line_style, symbol_colour, symbol_number;
  std::vector<PLFLT> line_width, symbol_scale;
  std::vector<std::string> texts, symbols;
  for (std::size_t k = 0; k < f.series.size(); ++k) {
    const Series& s = f.series[k];
    const PLINT colour = static_cast<PLINT>(1 + k % 10);
    plcol0(colour);
    std::vector<PLFLT> xs, ys;
    const auto flush = [&] {
      if (xs.size() >= 2 && s.mark == Mark::Line)
        plline(static_cast<PLINT>(xs.size()), xs.data(), ys.data());
      if (!xs.empty() && (s.mark == Mark::Dots || xs.size() == 1))
        plstring(static_cast<PLINT>(xs.size()), xs.data(), ys.data(), "#(727)");
      xs.clear();
      ys.clear();
    };
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const double x = to_axis(s.x[i], f.x, ux), y = to_axis(s.y[i], f.y, uy);
      if (std::isfinite(x) && std::isfinite(y)) {
        xs.push_back(x);
        ys.push_back(y);
      } else {
        flush();  // a gap in the data is a gap in the line
      }
    }
    flush();
    if (s.label.empty()) continue;
    opt.push_back(s.mark == Mark::Line ? PL_LEGEND_LINE : PL_LEGEND_SYMBOL);
    texts.push_back(escaped(s.label));
    text_colour.push_back(kForeground);
    line_colour.push_back(colour);
    line_style.push_back(1);
    line_width.push_back(1.0);
    symbol_colour.push_back(colour);
    symbol_scale.push_back(1.0);
    symbol_number.push_back(3);
    symbols.push_back("#(727)");
  }

  for (const Point& p : f.points) {
    PLFLT x = to_axis(p.x, f.x, ux), y = to_axis(p.y, f.y, uy);
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    plcol0(kForeground);
    plpoin(1, &x, &y, 4);
    plschr(0, 0.8);
    // Right of the point, or left of it in the last quarter of the axis, where a label written
    // rightwards would run out of the frame and be cut (a curve that ends at a marked point).
    const bool left = x > x0 + 0.75 * (x1 - x0);
    plptex(x + (left ? -0.01 : 0.01) * (x1 - x0), y, 1.0, 0.0, left ? 1.0 : 0.0,
           escaped(p.label).c_str());
    plschr(0, 1.0);
  }

  // A legend longer than the plot is tall hides the curves: past kMaxLegendEntries the rest are
  // counted in one line (their curves are still drawn).
  if (texts.size() > kMaxLegendEntries) {
    const std::size_t hidden = texts.size() - (kMaxLegendEntries - 1);
    for (auto* v : {&text_colour, &line_colour, &symbol_colour, &symbol_number, &line_style})
      v->resize(kMaxLegendEntries);
    opt.resize(kMaxLegendEntries);
    texts.resize(kMaxLegendEntries);
    symbols.resize(kMaxLegendEntries);
    line_width.resize(kMaxLegendEntries);
    symbol_scale.resize(kMaxLegendEntries);
    opt.back() = PL_LEGEND_NONE;
    texts.back() = "and " + std::to_string(hidden) + " more";
  }
  // One curve needs no legend: the title names it.
  if (texts.size() > 1) {
    std::vector<const char*> text_ptrs, symbol_ptrs;
    for (const auto& t : texts) text_ptrs.push_back(t.c_str());
    for (const auto& t : symbols) symbol_ptrs.push_back(t.c_str());
    PLFLT width = 0, height = 0;
    plschr(0, 0.8);
    pllegend(&width, &height, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
             // Top left: a force curve that rises with depth leaves that corner empty.
             PL_POSITION_TOP | PL_POSITION_LEFT | PL_POSITION_INSIDE, 0.02, 0.02, 0.08, 0,
             kForeground, 1, 0, 0, static_cast<PLINT>(texts.size()), opt.data(), 1.0, 1.0, 1.5, 0.0,
             text_colour.data(), text_ptrs.data(), nullptr, nullptr, nullptr, nullptr,
             line_colour.data(), line_style.data(), line_width.data(), symbol_colour.data(),
             symbol_scale.data(), symbol_number.data(), symbol_ptrs.data());
    plschr(0, 1.0);
  }
  plend1();

  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw InputError(file.string() + ": cannot write the plot (" + ec.message() + ")");
  }
}

std::string svg_element(const Figure& figure) {
  // PLplot writes only to files: one of our own per call (process id and a counter), removed
  // at once.
  static std::atomic<unsigned> counter{0};
  const unsigned number = counter.fetch_add(1);
  const auto file =
      std::filesystem::temp_directory_path() /
      ("mneedle-figure-" + std::to_string(::getpid()) + "-" + std::to_string(number) + ".svg");
  write_svg(file, figure);
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  std::error_code ec;
  std::filesystem::remove(file, ec);
  std::string svg = text.str();
  const auto start = svg.find("<svg");
  if (start == std::string::npos) throw InputError("plot: PLplot wrote no <svg> element");
  svg = svg.substr(start);
  // PLplot numbers its clip paths from 0 in every file: figures inline in one page would share
  // the ids (and clip with each other's paths). Each element gets this call's number.
  const std::string prefix = "mneedle-figure-" + std::to_string(number) + "-";
  for (std::size_t pos = 0; (pos = svg.find("text-clipping", pos)) != std::string::npos;
       pos += prefix.size() + 13)
    svg.insert(pos, prefix);
  return svg;
}

}  // namespace mneedle::plot
