// rvr diff: two image files compared, reported as OpenImageIO's idiff reports them.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "cli_exit.h"
#include "commands.h"
#include "rvr/compare/compare.h"
#include "rvr/image_codec/image_io.h"

namespace rvr::cli {

namespace {

// "inf" and "nan" as idiff prints them, anything else as %g.
std::string number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{:g}", v);
}

std::string channel_name(const Image& a, const Image& b, int c) {
  if (size_t(c) < a.channel_names.size()) return a.channel_names[size_t(c)];
  if (size_t(c) < b.channel_names.size()) return b.channel_names[size_t(c)];
  return fmt::format("channel {}", c);
}

std::string pixel_values(const Image& image, int x, int y) {
  std::string s;
  for (int c = 0; c < image.channels; ++c)
    s += fmt::format("{}{}", c ? ", " : "", image.at(x, y, c));
  return s;
}

}  // namespace

int run_diff(const DiffArgs& d) {
  if (!d.out.empty()) refuse_overwriting_inputs({d.a, d.b}, {d.out});
  Image a = take(read_image(d.a));
  Image b = take(read_image(d.b));
  ImageDiff diff = take(diff_images(a, b, d.thresholds));
  if (!d.out.empty()) check(write_image(d.out, diff_heat_map(a, b, 0.1f), false));
  DiffVerdict verdict = diff_verdict(diff, d.thresholds);
  const bool rmse_failed = d.fail_above && diff.rmse > *d.fail_above;
  if (rmse_failed) verdict = DiffVerdict::Failure;

  const double pixels = double(std::max<size_t>(diff.pixels, 1));
  std::string report = fmt::format("Comparing \"{}\" and \"{}\"\n", d.a, d.b);
  report += "  Mean error = " + number(diff.mean_abs) + "\n";
  report += "  RMS error = " + number(diff.rmse) + "\n";
  report += "  Peak SNR = " + number(diff.psnr_db) + "\n";
  report += "  Max error  = " + number(diff.max_abs);
  if (diff.max_abs != 0.0)
    report +=
        fmt::format(" @ ({}, {}, {})  values are {} vs {}", diff.max_x, diff.max_y,
                    channel_name(a, b, diff.max_channel), pixel_values(a, diff.max_x, diff.max_y),
                    pixel_values(b, diff.max_x, diff.max_y));
  report += "\n";
  report += fmt::format("  {} pixels ({:1.3g}%) over {}\n", diff.warn_pixels,
                        100.0 * double(diff.warn_pixels) / pixels, d.thresholds.warn);
  report += fmt::format("  {} pixels ({:1.3g}%) over {}\n", diff.fail_pixels,
                        100.0 * double(diff.fail_pixels) / pixels, d.thresholds.fail);
  if (rmse_failed)
    report += fmt::format("  RMS error {} above {}\n", number(diff.rmse), number(*d.fail_above));
  report += std::string(to_string(verdict)) + "\n";
  std::fputs(report.c_str(), stdout);
  return verdict == DiffVerdict::Pass ? 0 : 1;
}

}  // namespace rvr::cli
