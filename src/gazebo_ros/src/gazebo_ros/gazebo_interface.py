"""gazebo_ros's wrappers around the /gazebo services, with the original's names, arguments and
return values, so users' scripts that ``from gazebo_ros import gazebo_interface`` work against
thorvald_sim's simulator (which offers the services).

Each waits for its service (for ever, as the original), calls it, logs the status and returns the
response's ``success``; a failed call prints "Service call failed: ..." and returns None, as the
original does. One difference: the original's set_model_configuration_client sleeps one wall second
before calling (its "temporary hack" for Gazebo's issue #93, a race with the spawn); here the spawn
answers once the model is in the world, so it calls at once.

The original module also star-imports gazebo_msgs' messages and services and geometry_msgs' Point,
Pose, Quaternion, Twist and Wrench; so does this one, for scripts that took them from here.
"""

import rospy
from geometry_msgs.msg import Point, Pose, Quaternion, Twist, Wrench  # noqa: F401  (the original's names)

from gazebo_msgs.msg import *  # noqa: F403  (the original's names)
from gazebo_msgs.srv import *  # noqa: F403
from gazebo_msgs.srv import SetModelConfiguration, SpawnModel


def _spawn(service, model_name, model_xml, robot_namespace, initial_pose, reference_frame, gazebo_namespace):  # noqa: PLR0917
    name = gazebo_namespace + "/" + service
    rospy.loginfo("Waiting for service %s", name)
    rospy.wait_for_service(name)
    try:
        spawn = rospy.ServiceProxy(name, SpawnModel)
        rospy.loginfo("Calling service %s", name)
        resp = spawn(model_name, model_xml, robot_namespace, initial_pose, reference_frame)
        rospy.loginfo("Spawn status: %s", resp.status_message)
        return resp.success
    except rospy.ServiceException as e:
        print(f"Service call failed: {e}")
        return None


def spawn_sdf_model_client(  # noqa: PLR0917  (the original's signature)
    model_name, model_xml, robot_namespace, initial_pose, reference_frame, gazebo_namespace
):
    """<gazebo_namespace>/spawn_sdf_model: the response's success (None when the call failed)."""
    return _spawn(
        "spawn_sdf_model", model_name, model_xml, robot_namespace, initial_pose, reference_frame, gazebo_namespace
    )


def spawn_urdf_model_client(  # noqa: PLR0917  (the original's signature)
    model_name, model_xml, robot_namespace, initial_pose, reference_frame, gazebo_namespace
):
    """<gazebo_namespace>/spawn_urdf_model: the response's success (None when the call failed). A
    Thorvald description spawns as a robot with its topics in robot_namespace."""
    return _spawn(
        "spawn_urdf_model", model_name, model_xml, robot_namespace, initial_pose, reference_frame, gazebo_namespace
    )


def set_model_configuration_client(model_name, model_param_name, joint_names, joint_positions, gazebo_namespace):
    """<gazebo_namespace>/set_model_configuration: the joints at the positions [rad or m]; the
    response's success (None when the call failed)."""
    name = gazebo_namespace + "/set_model_configuration"
    rospy.loginfo("Waiting for service %s", name)
    rospy.wait_for_service(name)
    try:
        set_configuration = rospy.ServiceProxy(name, SetModelConfiguration)
        rospy.loginfo("Calling service %s", name)
        resp = set_configuration(model_name, model_param_name, joint_names, joint_positions)
        rospy.loginfo("Set model configuration status: %s", resp.status_message)
        return resp.success
    except rospy.ServiceException as e:
        print(f"Service call failed: {e}")
        return None
