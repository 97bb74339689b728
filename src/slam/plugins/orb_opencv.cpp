// libvola_opencv.so: ORB and SIFT keypoints and descriptors through OpenCV (orb_plugin.hpp).
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include <cstring>
#include <type_traits>

#include "../orb_plugin.hpp"

namespace vola::slam::plugin {

namespace {

std::vector<OrbKeypoint> detect_orb(const std::uint8_t* grey, std::uint32_t width, std::uint32_t height,
                                    int max_features, int fast_threshold) {
  // OpenCV only reads the pixels: the Mat wraps them without a copy.
  const cv::Mat image(static_cast<int>(height), static_cast<int>(width), CV_8UC1, const_cast<std::uint8_t*>(grey));
  cv::Ptr<cv::ORB> orb = cv::ORB::create(max_features, 1.2f, 8, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, fast_threshold);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  orb->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
  std::vector<OrbKeypoint> out(keypoints.size());
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    out[i].x = keypoints[i].pt.x;
    out[i].y = keypoints[i].pt.y;
    std::memcpy(out[i].descriptor.data(), descriptors.ptr<std::uint8_t>(static_cast<int>(i)), 32);
  }
  return out;
}

std::vector<SiftKeypoint> detect_sift(const std::uint8_t* grey, std::uint32_t width, std::uint32_t height,
                                      int max_features, double contrast_threshold) {
  const cv::Mat image(static_cast<int>(height), static_cast<int>(width), CV_8UC1, const_cast<std::uint8_t*>(grey));
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(max_features, 3, contrast_threshold);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  sift->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
  std::vector<SiftKeypoint> out(keypoints.size());
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    out[i].x = keypoints[i].pt.x;
    out[i].y = keypoints[i].pt.y;
    const float* d = descriptors.ptr<float>(static_cast<int>(i));
    for (std::size_t j = 0; j < 128; ++j) out[i].descriptor[j] = cv::saturate_cast<std::uint8_t>(d[j]);
  }
  return out;
}

}  // namespace

}  // namespace vola::slam::plugin

extern "C" {
const char* vola_plugin_version() { return vola::plugin::kPluginVersion; }
void vola_plugin_detect_orb(const std::uint8_t* grey, std::uint32_t width, std::uint32_t height, int max_features,
                            int fast_threshold, std::vector<vola::slam::plugin::OrbKeypoint>& out,
                            vola::plugin::PluginFailure& failure) {
  vola::plugin::capture_failure(failure, [&] {
    out = vola::slam::plugin::detect_orb(grey, width, height, max_features, fast_threshold);
  });
}
void vola_plugin_detect_sift(const std::uint8_t* grey, std::uint32_t width, std::uint32_t height, int max_features,
                             double contrast_threshold, std::vector<vola::slam::plugin::SiftKeypoint>& out,
                             vola::plugin::PluginFailure& failure) {
  vola::plugin::capture_failure(failure, [&] {
    out = vola::slam::plugin::detect_sift(grey, width, height, max_features, contrast_threshold);
  });
}
}
static_assert(std::is_same_v<decltype(&vola_plugin_detect_orb), vola::slam::plugin::DetectOrbEntry>);
static_assert(std::is_same_v<decltype(&vola_plugin_detect_sift), vola::slam::plugin::DetectSiftEntry>);
