#include "tools/config_yaml.hpp"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <functional>
#include <map>

#include "tools/dataset/input_error.hpp"

namespace parallax {
namespace {

using Setter = std::function<void(const YAML::Node&)>;
using Section = std::map<std::string, Setter>;

int LineOf(const YAML::Node& node) { return node.Mark().line >= 0 ? node.Mark().line + 1 : 0; }

template <typename T>
Setter Set(T* field) {
  return [field](const YAML::Node& node) { *field = node.as<T>(); };
}

std::map<std::string, Section> Sections(SystemOptions* o) {
  return {
      {"pyramid",
       {{"max_levels", Set(&o->pyramid.max_levels)},
        {"min_level_size", Set(&o->pyramid.min_level_size)}}},
      {"reference",
       {{"min_gradient", Set(&o->reference.min_gradient)},
        {"max_points_per_level", Set(&o->reference.max_points_per_level)}}},
      {"tracker",
       {{"finest_level", Set(&o->tracker.finest_level)},
        {"max_iterations", Set(&o->tracker.max_iterations)},
        {"pixel_noise_sigma", Set(&o->tracker.pixel_noise_sigma)},
        {"huber_threshold", Set(&o->tracker.huber_threshold)},
        {"estimate_affine", Set(&o->tracker.estimate_affine)},
        {"affine_prior_a", Set(&o->tracker.affine_prior_a)},
        {"affine_prior_b", Set(&o->tracker.affine_prior_b)},
        {"good_threshold", Set(&o->tracker.good_threshold)},
        {"suspect_good_ratio", Set(&o->tracker.suspect_good_ratio)},
        {"search_rotations_deg", Set(&o->tracker.search_rotations_deg)},
        {"velocity_rescale_ratio", Set(&o->tracker.velocity_rescale_ratio)},
        {"refine_margin", Set(&o->tracker.refine_margin)},
        {"min_reacquisition_points", Set(&o->tracker.min_reacquisition_points)},
        {"max_residual_jump", Set(&o->tracker.max_residual_jump)},
        {"min_good_ratio_ok", Set(&o->tracker.min_good_ratio_ok)},
        {"min_good_ratio_poor", Set(&o->tracker.min_good_ratio_poor)}}},
      {"depth",
       {{"min_gradient", Set(&o->depth.min_gradient)},
        {"pixel_noise_sigma", Set(&o->depth.pixel_noise_sigma)},
        {"max_search_length", Set(&o->depth.max_search_length)},
        {"max_search_length_new", Set(&o->depth.max_search_length_new)},
        {"min_search_length", Set(&o->depth.min_search_length)},
        {"baseline_sigma", Set(&o->depth.baseline_sigma)},
        {"rotation_sigma", Set(&o->depth.rotation_sigma)},
        {"max_variance", Set(&o->depth.max_variance)},
        {"converged_relative_sigma", Set(&o->depth.converged_relative_sigma)},
        {"converged_recheck", Set(&o->depth.converged_recheck)},
        {"seed", Set(&o->depth.seed)}}},
      {"system",
       {{"initialization",
         [o](const YAML::Node& node) {
           const std::string value = node.as<std::string>();
           if (value == "auto") {
             o->initialization = Initialization::kAuto;
           } else if (value == "random") {
             o->initialization = Initialization::kRandom;
           } else if (value == "two_view") {
             o->initialization = Initialization::kTwoView;
           } else {
             throw YAML::Exception(node.Mark(), "bad value (auto, random or two_view)");
           }
         }},
        {"auto_max_rotation_deg", Set(&o->auto_max_rotation_deg)},
        {"auto_max_direction_deg", Set(&o->auto_max_direction_deg)},
        {"auto_pair_residual_ratio", Set(&o->auto_pair_residual_ratio)},
        {"pair_refine_stride", Set(&o->pair_refine_stride)},
        {"restart_after_lost", Set(&o->restart_after_lost)},
        {"max_start_exposure_change", Set(&o->max_start_exposure_change)},
        {"min_start_texture", Set(&o->min_start_texture)},
        {"bootstrap_max_frames", Set(&o->bootstrap_max_frames)},
        {"bootstrap_min_parallax_deg", Set(&o->bootstrap.min_parallax_deg)},
        {"bootstrap_min_fallback_parallax_deg", Set(&o->bootstrap.min_fallback_parallax_deg)},
        {"bootstrap_parallax_points", Set(&o->bootstrap.parallax_points)},
        {"bootstrap_min_inliers", Set(&o->bootstrap.min_inliers)},
        {"bootstrap_max_homography_share", Set(&o->bootstrap.max_homography_share)},
        {"bootstrap_min_twin_cost_ratio", Set(&o->bootstrap.min_twin_cost_ratio)},
        {"bootstrap_max_offset_sigma", Set(&o->bootstrap.max_offset_sigma)},
        {"keyframe_distance", Set(&o->keyframe_distance)},
        {"keyframe_distance_in_image", Set(&o->keyframe_distance_in_image)},
        {"keyframe_rotation_deg", Set(&o->keyframe_rotation_deg)},
        {"keyframe_rotation_min_rate_deg", Set(&o->keyframe_rotation_min_rate_deg)},
        {"min_keyframe_usage", Set(&o->min_keyframe_usage)},
        {"min_keyframe_good_ratio", Set(&o->min_keyframe_good_ratio)},
        {"min_update_baseline", Set(&o->min_update_baseline)},
        {"min_frames_per_keyframe", Set(&o->min_frames_per_keyframe)},
        {"early_keyframe_usage", Set(&o->early_keyframe_usage)},
        {"recent_keyframes", Set(&o->recent_keyframes)},
        {"max_buffered_frames", Set(&o->max_buffered_frames)},
        {"max_buffered_megabytes", Set(&o->max_buffered_megabytes)},
        {"initialization_updates", Set(&o->initialization_updates)},
        {"update_direction", Set(&o->update_direction.enabled)},
        {"update_direction_weight", Set(&o->update_direction.essential_weight)},
        {"update_direction_rotation", Set(&o->update_direction.blend_rotation)},
        {"update_direction_reuse_max_rotation_deg",
         Set(&o->update_direction.reuse_max_rotation_deg)},
        {"update_direction_max_angle_deg", Set(&o->update_direction.max_angle_deg)},
        {"update_direction_min_baseline", Set(&o->update_direction.min_relative_baseline)},
        {"update_direction_recheck_growth", Set(&o->update_direction.recheck_growth)},
        {"update_direction_max_axis_angle_deg", Set(&o->update_direction.max_axis_angle_deg)},
        {"update_direction_reuse_max_angle_deg", Set(&o->update_direction.reuse_max_angle_deg)},
        {"start_refinement", Set(&o->start_refinement.enabled)},
        {"start_refinement_coarsest_level", Set(&o->start_refinement.coarsest_level)},
        {"start_refinement_iterations", Set(&o->start_refinement.joint_iterations)},
        {"start_refinement_points", Set(&o->start_refinement.max_joint_points)},
        {"start_refinement_frames", Set(&o->start_refinement_frames)},
        {"start_refinement_max_point_sigma", Set(&o->start_refinement.max_point_relative_sigma)},
        {"keyframe_refinement", Set(&o->keyframe_refinement.enabled)},
        {"keyframe_refinement_frames", Set(&o->keyframe_refinement_frames)},
        {"keyframe_refinement_min_window", Set(&o->keyframe_refinement_min_window)},
        {"keyframe_refinement_max_point_sigma",
         Set(&o->keyframe_refinement.max_point_relative_sigma)},
        {"keyframe_window_capacity", Set(&o->keyframe_window_capacity)},
        {"optimize_graph", Set(&o->optimize_graph)},
        {"spread_keyframe_corrections", Set(&o->spread_keyframe_corrections)},
        {"spread_max_step_change", Set(&o->spread_max_step_change)},
        {"new_map_after_lost_s", Set(&o->new_map_after_lost_s)}}},
      {"backend",
       {{"neighbour_max_distance", Set(&o->backend.neighbour_max_distance)},
        {"neighbour_max_angle_deg", Set(&o->backend.neighbour_max_angle_deg)},
        {"max_neighbours", Set(&o->backend.max_neighbours)},
        {"max_reciprocal_mahalanobis", Set(&o->backend.max_reciprocal_mahalanobis)},
        {"information_scale", Set(&o->backend.information_scale)},
        {"fallback_odometry_information", Set(&o->backend.fallback_odometry_information)},
        {"fallback_from_median", Set(&o->backend.fallback_from_median)},
        {"odometry_from_alignment", Set(&o->backend.odometry_from_alignment)},
        {"optimizer_max_iterations", Set(&o->backend.optimizer.max_iterations)},
        {"alignment_finest_level", Set(&o->backend.alignment.finest_level)},
        {"optimizer_kernel_width", Set(&o->backend.optimizer.kernel_width)}}},
      {"loop_closure",
       {{"enabled", Set(&o->loop_closure.enabled)},
        {"orb_features", Set(&o->loop_closure.place.orb.max_features)},
        {"max_match_distance", Set(&o->loop_closure.place.max_match_distance)},
        {"match_ratio", Set(&o->loop_closure.place.match_ratio)},
        {"exclude_recent_keyframes", Set(&o->loop_closure.exclude_recent_keyframes)},
        {"min_score", Set(&o->loop_closure.min_score)},
        {"max_candidates", Set(&o->loop_closure.max_candidates)},
        {"consistency", Set(&o->loop_closure.consistency)},
        {"min_matches", Set(&o->loop_closure.min_matches)},
        {"max_relative_depth_std", Set(&o->loop_closure.max_relative_depth_std)},
        {"max_correction_per_path", Set(&o->loop_closure.max_correction_per_path)},
        {"reciprocal_median", Set(&o->loop_closure.reciprocal_median)},
        {"ransac_min_inliers", Set(&o->loop_closure.ransac.min_inliers)},
        {"ransac_max_iterations", Set(&o->loop_closure.ransac.max_iterations)},
        {"ransac_max_reprojection_chi2", Set(&o->loop_closure.ransac.max_reprojection_chi2)},
        {"optimizer_max_iterations", Set(&o->loop_closure.optimizer.max_iterations)}}},
      {"relocalization",
       {{"enabled", Set(&o->relocalization.enabled)},
        {"max_candidates", Set(&o->relocalization.max_candidates)},
        {"min_score", Set(&o->relocalization.min_score)},
        {"min_matches", Set(&o->relocalization.min_matches)},
        {"min_inliers", Set(&o->relocalization.min_inliers)},
        {"max_reprojection_px", Set(&o->relocalization.max_reprojection_px)},
        {"ransac_iterations", Set(&o->relocalization.ransac_iterations)},
        {"max_relative_depth_std", Set(&o->relocalization.max_relative_depth_std)}}},
      {"realtime",
       {{"max_pending_frames", Set(&o->realtime.max_pending_frames)},
        {"tracking_threads", Set(&o->realtime.tracking_threads)},
        {"mapping_threads", Set(&o->realtime.mapping_threads)},
        {"waited_mapping_threads", Set(&o->realtime.waited_mapping_threads)},
        {"keyframe_mapping_threads", Set(&o->realtime.keyframe_mapping_threads)},
        {"opencv_threads", Set(&o->realtime.opencv_threads)},
        {"keyframe_wait_factor", Set(&o->realtime.keyframe_wait_factor)},
        {"keyframe_pacing_ms", Set(&o->realtime.keyframe_pacing_ms)},
        {"bridge_keyframe_requests", Set(&o->realtime.bridge_keyframe_requests)},
        {"bridge_min_keyframe_updates", Set(&o->realtime.bridge_min_keyframe_updates)},
        {"snapshot_keyframe_poses", Set(&o->realtime.snapshot_keyframe_poses)},
        {"backend_threads", Set(&o->realtime.backend_threads)},
        {"backend_nice", Set(&o->realtime.backend_nice)},
        {"backend_drain_threads", Set(&o->realtime.backend_drain_threads)},
        {"catch_up_refinements", Set(&o->realtime.catch_up_refinements)},
        {"answer_start_at_once", Set(&o->realtime.answer_start_at_once)},
        {"max_queued_start_frames", Set(&o->realtime.max_queued_start_frames)}}},
  };
}

/// `root` parsed from `path` (a file name, or the name given to a YAML string).
void ApplyConfigRoot(const YAML::Node& root, const std::string& path, SystemOptions* options) {
  if (root.IsNull()) return;  // empty file: defaults
  if (!root.IsMap()) throw InputError(path, "configuration must be a YAML mapping of sections");
  SystemOptions updated = *options;
  auto sections = Sections(&updated);
  for (const auto& section : root) {
    const std::string name = section.first.as<std::string>();
    const auto found = sections.find(name);
    if (found == sections.end()) {
      throw InputError(path, LineOf(section.first),
                       "unknown section '" + name +
                           "' (expected pyramid, reference, tracker, depth, system, backend, "
                           "loop_closure, relocalization or realtime)");
    }
    if (!section.second.IsMap())
      throw InputError(path, LineOf(section.second), "section '" + name + "' must be a mapping");
    for (const auto& entry : section.second) {
      const std::string key = entry.first.as<std::string>();
      std::string qualified = name;
      qualified += '.';
      qualified += key;
      const auto setter = found->second.find(key);
      if (setter == found->second.end()) {
        throw InputError(path, LineOf(entry.first), "unknown key '" + qualified + "'");
      }
      try {
        setter->second(entry.second);
      } catch (const YAML::Exception&) {
        throw InputError(path, LineOf(entry.second),
                         "'" + qualified + "' has a value of the wrong type");
      }
    }
  }
  try {
    updated.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(path, e.what());
  }
  *options = updated;
}

}  // namespace

void ApplyConfigYaml(const std::string& path, SystemOptions* options) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open configuration file");
  YAML::Node root;
  try {
    root = YAML::Load(in);
  } catch (const YAML::ParserException& e) {
    throw InputError(path, e.mark.line + 1, "YAML syntax error: " + e.msg);
  }
  ApplyConfigRoot(root, path, options);
}

void ApplyConfigYamlText(const std::string& text, const std::string& name, SystemOptions* options) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw InputError(name, e.mark.line + 1, "YAML syntax error: " + e.msg);
  }
  ApplyConfigRoot(root, name, options);
}

}  // namespace parallax
