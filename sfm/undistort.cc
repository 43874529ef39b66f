#include "sfm/undistort.h"

#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace parallax {

Camera PinholeOf(const Camera& camera) {
  return MakePinholeCamera(camera.id, camera.width, camera.height, camera.FocalX(),
                           camera.FocalY(), camera.PrincipalX(), camera.PrincipalY());
}

void UndistortPhoto(const Camera& camera, const std::filesystem::path& input,
                    const std::filesystem::path& output) {
  if (!IsProjectionSupported(camera.model)) {
    throw InternalError("UndistortPhoto: camera " + std::to_string(camera.id) +
                        ": projection not supported for its model");
  }
  // Unchanged: keeps 16-bit and alpha, and does not apply EXIF orientation (COLMAP does not).
  const cv::Mat photo = cv::imread(input.string(), cv::IMREAD_UNCHANGED);
  if (photo.empty()) throw BadInputError(input.string() + ": cannot read the image");
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  if (photo.cols != width || photo.rows != height) {
    throw BadInputError(input.string() + ": " + std::to_string(photo.cols) + "x" +
                        std::to_string(photo.rows) + " pixels, camera " +
                        std::to_string(width) + "x" + std::to_string(height));
  }
  const double fx = camera.FocalX(), fy = camera.FocalY();
  const double cx = camera.PrincipalX(), cy = camera.PrincipalY();
  // Where each undistorted pixel centre lies in the photo. COLMAP puts pixel centres at
  // integer + 0.5, OpenCV's remap at integers.
  cv::Mat map_x(height, width, CV_32F), map_y(height, width, CV_32F);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Eigen::Vector2d distorted =
          camera.Distort(Eigen::Vector2d((x + 0.5 - cx) / fx, (y + 0.5 - cy) / fy));
      map_x.at<float>(y, x) = static_cast<float>(fx * distorted.x() + cx - 0.5);
      map_y.at<float>(y, x) = static_cast<float>(fy * distorted.y() + cy - 0.5);
    }
  }
  cv::Mat undistorted;
  cv::remap(photo, undistorted, map_x, map_y, cv::INTER_LANCZOS4, cv::BORDER_REPLICATE);
  std::vector<int> parameters;
  const std::string extension = output.extension().string();
  if (extension == ".jpg" || extension == ".jpeg" || extension == ".JPG" || extension == ".JPEG") {
    parameters = {cv::IMWRITE_JPEG_QUALITY, 100};
  }
  if (!cv::imwrite(output.string(), undistorted, parameters)) {
    throw BadInputError(output.string() + ": cannot write the undistorted image");
  }
}

}  // namespace parallax
