#pragma once
// The sphere-map ("matcap") specular material of the source texts: for a fixed light and view,
// the Blinn-Phong highlight precomputed into a texture indexed by the surface normal in camera
// coordinates, so a fragment's specular is one texture lookup. It assumes every fragment is
// seen along the optical axis (an orthographic view), which is close for a narrow field of view.
#include <vector>

#include <Eigen/Core>

namespace parallax {

// `size` x `size` texels, row by row, texel (x, y) holding the highlight
// specular * max(n.h, 0)^shininess (0 where n.l <= 0) for the unit normal
// n = (s, t, -sqrt(1 - s^2 - t^2)) with s, t = 2 (x, y + 0.5) / size - 1: camera coordinates
// (x right, y down, z forward), facing the eye; h halves the way between the light's direction
// and the eye's, (0, 0, -1). Texels outside the unit disc take their value on its rim.
std::vector<float> BlinnPhongMatcap(int size, const Eigen::Vector3d& towards_light_in_camera, double specular,
                                    double shininess);

}  // namespace parallax
