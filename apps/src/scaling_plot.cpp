// bench scaling's plot: real-time factor and control frames per second
// against robots, log scale, beside USARSim's published figures.
#include "scaling_plot.hpp"

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "cli.hpp"

namespace simsoccer::apps {

void writeScalingPlot(const std::vector<ScalingPoint>& rows, const std::filesystem::path& file) {
  const int W = 900, H = 560, L = 80, R = 30, T = 50, B = 70;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  const double xmin = std::log10(1.0), xmax = std::log10(24.0), ymin = -1.0,
               ymax = 4.0;  // 0.1 .. 10^4
  auto px = [&](double robots, double value) {
    const double x = L + (std::log10(robots) - xmin) / (xmax - xmin) * (W - L - R);
    const double y =
        H - B - (std::log10(std::max(value, 0.1)) - ymin) / (ymax - ymin) * (H - T - B);
    return cv::Point(static_cast<int>(x), static_cast<int>(y));
  };
  for (int e = -1; e <= 4; ++e) {
    cv::line(img, px(1, std::pow(10, e)), px(24, std::pow(10, e)), cv::Scalar(225, 225, 225), 1);
    cv::putText(img, fmt(std::pow(10, e), e < 0 ? 1 : 0),
                px(1, std::pow(10, e)) + cv::Point(-60, 5), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(80, 80, 80), 1, cv::LINE_AA);
  }
  for (int n : {1, 2, 4, 8, 11, 22}) {
    cv::line(img, px(n, 0.1), px(n, 1e4), cv::Scalar(235, 235, 235), 1);
    cv::putText(img, std::to_string(n), px(n, 0.1) + cv::Point(-8, 22), cv::FONT_HERSHEY_SIMPLEX,
                0.5, cv::Scalar(60, 60, 60), 1, cv::LINE_AA);
  }
  cv::putText(img, "robots", cv::Point(W / 2 - 30, H - 20), cv::FONT_HERSHEY_SIMPLEX, 0.6,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  auto series = [&](const std::vector<std::pair<double, double>>& pts, const cv::Scalar& colour) {
    for (size_t i = 0; i < pts.size(); ++i) {
      cv::circle(img, px(pts[i].first, pts[i].second), 5, colour, cv::FILLED, cv::LINE_AA);
      if (i)
        cv::line(img, px(pts[i - 1].first, pts[i - 1].second), px(pts[i].first, pts[i].second),
                 colour, 2, cv::LINE_AA);
    }
  };
  std::vector<std::pair<double, double>> fps, rtf;
  for (const ScalingPoint& r : rows) {
    fps.emplace_back(r.robots, r.fps);
    rtf.emplace_back(r.robots, r.rtf);
  }
  series({{1, 110}, {2, 55}, {3, 30}, {4, 10}}, cv::Scalar(40, 40, 200));
  series(fps, cv::Scalar(200, 90, 20));
  series(rtf, cv::Scalar(30, 150, 30));
  cv::putText(img, "simsoccer control frames/s (100 per simulated s)", cv::Point(L + 10, T - 25),
              cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(200, 90, 20), 1, cv::LINE_AA);
  cv::putText(img, "simsoccer real-time factor", cv::Point(L + 10, T - 8), cv::FONT_HERSHEY_SIMPLEX,
              0.5, cv::Scalar(30, 150, 30), 1, cv::LINE_AA);
  cv::putText(img, "USARSim fps (published, 1-4 Naos)", cv::Point(L + 450, T - 25),
              cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(40, 40, 200), 1, cv::LINE_AA);
  if (!cv::imwrite(file.string(), img))
    throw std::runtime_error(file.string() + ": cannot write the plot");
}

}  // namespace simsoccer::apps
