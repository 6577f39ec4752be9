// The production services known to offline tools (replay, evaluation). A service is listed
// here once its <name>_service.h exists; it is registered when its target is built.
#include "services/replay/component_registry.h"

#ifdef BOOKGRASP_HAVE_MARKER_DETECTOR
#include "services/marker_detector/marker_detector_service.h"
#endif
#ifdef BOOKGRASP_HAVE_BWH_DETECTOR
#include "services/bwh_detector/bwh_detector_service.h"
#endif
#ifdef BOOKGRASP_HAVE_BSWH_DETECTOR
#include "services/bswh_detector/bswh_detector_service.h"
#endif
#ifdef BOOKGRASP_HAVE_ARBITER
#include "services/arbiter/arbiter_service.h"
#endif
#ifdef BOOKGRASP_HAVE_COORDINATOR
#include "services/coordinator/coordinator_service.h"
#endif
#ifdef BOOKGRASP_HAVE_STEREO_CAMERA
#include "services/stereo_camera/stereo_camera_service.h"
#endif
#ifdef BOOKGRASP_HAVE_HAND_CAMERA
#include "services/hand_camera/hand_camera_service.h"
#endif
#ifdef BOOKGRASP_HAVE_ARM_DRIVER
#include "services/arm_driver/arm_driver_service.h"
#endif
#ifdef BOOKGRASP_HAVE_BWS_DETECTOR
#include "services/bws_detector/bws_detector_service.h"
#endif
#ifdef BOOKGRASP_HAVE_PLANNER
#include "services/planner/planner_service.h"
#endif
#ifdef BOOKGRASP_HAVE_VISUAL_SERVO
#include "services/visual_servo/visual_servo_service.h"
#endif

namespace bookgrasp {

ComponentRegistry project_services() {
  ComponentRegistry r;
#ifdef BOOKGRASP_HAVE_MARKER_DETECTOR
  r.add(marker_detector_service());
#endif
#ifdef BOOKGRASP_HAVE_BWH_DETECTOR
  r.add(bwh_detector_service());
#endif
#ifdef BOOKGRASP_HAVE_BSWH_DETECTOR
  r.add(bswh_detector_service());
#endif
#ifdef BOOKGRASP_HAVE_ARBITER
  r.add(arbiter_service());
#endif
#ifdef BOOKGRASP_HAVE_COORDINATOR
  r.add(coordinator_service());
#endif
#ifdef BOOKGRASP_HAVE_STEREO_CAMERA
  r.add(stereo_camera_service());
#endif
#ifdef BOOKGRASP_HAVE_HAND_CAMERA
  r.add(hand_camera_service());
#endif
#ifdef BOOKGRASP_HAVE_ARM_DRIVER
  r.add(arm_driver_service());
#endif
#ifdef BOOKGRASP_HAVE_BWS_DETECTOR
  r.add(bws_detector_service());
#endif
#ifdef BOOKGRASP_HAVE_PLANNER
  r.add(planner_service());
#endif
#ifdef BOOKGRASP_HAVE_VISUAL_SERVO
  r.add(visual_servo_service());
#endif
  return r;
}

}  // namespace bookgrasp
