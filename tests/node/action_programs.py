"""rclpy action programs for the action tests, written as ROS 2's examples write them.

The server follows ros2/examples' minimal_action_server (goal, cancel and execute callbacks;
a coroutine execute callback under a MultiThreadedExecutor with a reentrant group) with
options for the other variants; the clients follow minimal_action_client (feedback, result)
and its cancelling variant. Our own code, run unmodified through rosl's rclpy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pathlib import Path

RUN_AS_RCLPY = (
    "import rosl.compat; rosl.compat.install(force=True); import runpy, sys; "
    "sys.argv = sys.argv[1:]; runpy.run_path(sys.argv[0], run_name='__main__')"
)

SERVER = """
import sys
import threading
import time

import rclpy
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.task import Future

from example_interfaces.action import Fibonacci

OPTIONS = dict(zip(sys.argv[1::2], sys.argv[2::2]))
DELAY = float(OPTIONS.get("--delay", "0.1"))


class FibonacciServer(Node):
    def __init__(self):
        super().__init__("fibonacci_server")
        self.cancel_seen = threading.Event()
        extra = {}
        if OPTIONS.get("--executor", "multi") == "multi":
            extra["callback_group"] = ReentrantCallbackGroup()
        execute = {
            "coroutine": self.execute_coroutine,
            "plain": self.execute_plain,
            "awaiting": self.execute_awaiting,
        }[OPTIONS.get("--execute", "coroutine")]
        self._action_server = ActionServer(
            self,
            Fibonacci,
            "fibonacci",
            execute_callback=execute,
            goal_callback=self.goal_callback,
            cancel_callback=self.cancel_callback,
            result_timeout=float(OPTIONS.get("--result-timeout", "900")),
            **extra,
        )
        print("ready", flush=True)

    def goal_callback(self, goal_request):
        print(f"goal request: order {goal_request.order}", flush=True)
        if goal_request.order == 99:
            raise RuntimeError("no goals of order 99")
        return GoalResponse.ACCEPT if goal_request.order >= 0 else GoalResponse.REJECT

    def cancel_callback(self, goal_handle):
        print("cancel request", flush=True)
        self.cancel_seen.set()
        if OPTIONS.get("--cancel", "accept") == "accept":
            return CancelResponse.ACCEPT
        return CancelResponse.REJECT

    def steps(self, goal_handle):
        feedback_msg = Fibonacci.Feedback()
        feedback_msg.sequence = [0, 1]
        if OPTIONS.get("--hold") == "until-cancel":  # finish only after a cancel request
            self.cancel_seen.wait(60)
        for i in range(1, goal_handle.request.order):
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                print("goal canceled", flush=True)
                return Fibonacci.Result()
            feedback_msg.sequence.append(feedback_msg.sequence[i] + feedback_msg.sequence[i - 1])
            goal_handle.publish_feedback(feedback_msg)
            time.sleep(DELAY)
        goal_handle.succeed()
        result = Fibonacci.Result()
        result.sequence = feedback_msg.sequence
        print(f"result: {list(result.sequence)}", flush=True)
        return result

    async def execute_coroutine(self, goal_handle):
        return self.steps(goal_handle)

    def execute_plain(self, goal_handle):
        return self.steps(goal_handle)

    async def execute_awaiting(self, goal_handle):
        # suspends on a future a timer completes: the executor runs other callbacks meanwhile
        ready = Future()
        timer = self.create_timer(0.05, lambda: ready.done() or ready.set_result(True))
        await ready
        timer.cancel()
        print("awaited", flush=True)
        return self.steps(goal_handle)


def main():
    rclpy.init()
    node = FibonacciServer()
    if OPTIONS.get("--executor", "multi") == "multi":
        executor = MultiThreadedExecutor()
    else:
        executor = SingleThreadedExecutor()
    rclpy.spin(node, executor=executor)


if __name__ == "__main__":
    main()
"""

CLIENT = """
import rclpy
from action_msgs.msg import GoalStatus
from rclpy.action import ActionClient
from rclpy.node import Node

from example_interfaces.action import Fibonacci


class MinimalActionClient(Node):
    def __init__(self):
        super().__init__("minimal_action_client")
        self._action_client = ActionClient(self, Fibonacci, "fibonacci")

    def goal_response_callback(self, future):
        goal_handle = future.result()
        if not goal_handle.accepted:
            print("Goal rejected :(", flush=True)
            return
        print("Goal accepted :)", flush=True)
        self._get_result_future = goal_handle.get_result_async()
        self._get_result_future.add_done_callback(self.get_result_callback)

    def feedback_callback(self, feedback):
        print(f"Received feedback: {list(feedback.feedback.sequence)}", flush=True)

    def get_result_callback(self, future):
        result = future.result().result
        status = future.result().status
        if status == GoalStatus.STATUS_SUCCEEDED:
            print(f"Goal succeeded! Result: {list(result.sequence)}", flush=True)
        else:
            print(f"Goal failed with status: {status}", flush=True)
        rclpy.shutdown()

    def send_goal(self):
        self._action_client.wait_for_server()
        goal_msg = Fibonacci.Goal()
        goal_msg.order = 10
        self._send_goal_future = self._action_client.send_goal_async(
            goal_msg, feedback_callback=self.feedback_callback
        )
        self._send_goal_future.add_done_callback(self.goal_response_callback)


def main():
    rclpy.init()
    action_client = MinimalActionClient()
    action_client.send_goal()
    rclpy.spin(action_client)


if __name__ == "__main__":
    main()
"""

CANCELLING_CLIENT = """
import rclpy
from rclpy.action import ActionClient
from rclpy.node import Node

from example_interfaces.action import Fibonacci


class MinimalActionClient(Node):
    def __init__(self):
        super().__init__("minimal_action_client")
        self._action_client = ActionClient(self, Fibonacci, "fibonacci")

    def cancel_done(self, future):
        cancel_response = future.result()
        if len(cancel_response.goals_canceling) > 0:
            print("Goal successfully canceled", flush=True)
        else:
            print(f"Goal failed to cancel: code {cancel_response.return_code}", flush=True)
        rclpy.shutdown()

    def goal_response_callback(self, future):
        goal_handle = future.result()
        if not goal_handle.accepted:
            print("Goal rejected :(", flush=True)
            return
        self._goal_handle = goal_handle
        print("Goal accepted :)", flush=True)

    def feedback_callback(self, feedback):
        print(f"Received feedback: {list(feedback.feedback.sequence)}", flush=True)
        if len(feedback.feedback.sequence) >= 4 and self._timer is None:
            self._timer = self.create_timer(0.1, self.timer_callback)

    def timer_callback(self):
        print("Canceling goal", flush=True)
        future = self._goal_handle.cancel_goal_async()
        future.add_done_callback(self.cancel_done)
        self._timer.cancel()

    def send_goal(self):
        self._timer = None
        self._action_client.wait_for_server()
        goal_msg = Fibonacci.Goal()
        goal_msg.order = 40
        self._send_goal_future = self._action_client.send_goal_async(
            goal_msg, feedback_callback=self.feedback_callback
        )
        self._send_goal_future.add_done_callback(self.goal_response_callback)


def main():
    rclpy.init()
    action_client = MinimalActionClient()
    action_client.send_goal()
    rclpy.spin(action_client)


if __name__ == "__main__":
    main()
"""


def write(folder: Path, name: str, source: str) -> str:
    """Write a program and return its path."""
    path = folder / name
    path.write_text(source.lstrip())
    return str(path)


TUTORIAL_SERVER = """
import time

import rclpy
from rclpy.action import ActionServer
from rclpy.node import Node

from action_tutorials_interfaces.action import Fibonacci


class FibonacciActionServer(Node):

    def __init__(self):
        super().__init__('fibonacci_action_server')
        self._action_server = ActionServer(
            self,
            Fibonacci,
            'fibonacci',
            self.execute_callback)
        print('ready', flush=True)

    def execute_callback(self, goal_handle):
        self.get_logger().info('Executing goal...')
        feedback_msg = Fibonacci.Feedback()
        feedback_msg.partial_sequence = [0, 1]
        for i in range(1, goal_handle.request.order):
            feedback_msg.partial_sequence.append(
                feedback_msg.partial_sequence[i] + feedback_msg.partial_sequence[i-1])
            self.get_logger().info('Feedback: {0}'.format(feedback_msg.partial_sequence))
            goal_handle.publish_feedback(feedback_msg)
            time.sleep(0.05)
        goal_handle.succeed()
        result = Fibonacci.Result()
        result.sequence = feedback_msg.partial_sequence
        return result


def main(args=None):
    rclpy.init(args=args)
    fibonacci_action_server = FibonacciActionServer()
    rclpy.spin(fibonacci_action_server)


if __name__ == '__main__':
    main()
"""

TUTORIAL_CLIENT = """
import rclpy
from rclpy.action import ActionClient
from rclpy.node import Node

from action_tutorials_interfaces.action import Fibonacci


class FibonacciActionClient(Node):

    def __init__(self):
        super().__init__('fibonacci_action_client')
        self._action_client = ActionClient(self, Fibonacci, 'fibonacci')

    def send_goal(self, order):
        goal_msg = Fibonacci.Goal()
        goal_msg.order = order
        self._action_client.wait_for_server()
        self._send_goal_future = self._action_client.send_goal_async(
            goal_msg, feedback_callback=self.feedback_callback)
        self._send_goal_future.add_done_callback(self.goal_response_callback)

    def goal_response_callback(self, future):
        goal_handle = future.result()
        if not goal_handle.accepted:
            self.get_logger().info('Goal rejected :(')
            return
        self.get_logger().info('Goal accepted :)')
        self._get_result_future = goal_handle.get_result_async()
        self._get_result_future.add_done_callback(self.get_result_callback)

    def get_result_callback(self, future):
        result = future.result().result
        print('Result: {0}'.format(result.sequence), flush=True)
        rclpy.shutdown()

    def feedback_callback(self, feedback_msg):
        feedback = feedback_msg.feedback
        print('Received feedback: {0}'.format(feedback.partial_sequence), flush=True)


def main(args=None):
    rclpy.init(args=args)
    action_client = FibonacciActionClient()
    action_client.send_goal(5)
    rclpy.spin(action_client)


if __name__ == '__main__':
    main()
"""


QUEUE_SERVER = """
import collections
import sys
import threading
import time

import rclpy
from rclpy.action import ActionServer
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node

from example_interfaces.action import Fibonacci


def say(text):  # one write: two threads' lines never interleave (print writes twice)
    sys.stdout.write(text + '\\n')


class QueueServer(Node):
    \"\"\"Goals wait their turn: the accepted callback starts one and queues the others.\"\"\"

    def __init__(self):
        super().__init__('queue_server')
        self._goal_queue = collections.deque()
        self._goal_queue_lock = threading.Lock()
        self._current_goal = None
        self._first = True
        self._action_server = ActionServer(
            self, Fibonacci, 'fibonacci',
            handle_accepted_callback=self.handle_accepted_callback,
            execute_callback=self.execute_callback,
            callback_group=ReentrantCallbackGroup())
        say('ready')

    def handle_accepted_callback(self, goal_handle):
        with self._goal_queue_lock:
            if self._current_goal is not None:
                self._goal_queue.append(goal_handle)
                say(f'queued order {goal_handle.request.order}')
            else:
                self._current_goal = goal_handle
                self._current_goal.execute()

    def execute_callback(self, goal_handle):
        try:
            say(f'executing order {goal_handle.request.order}')
            if self._first:  # (the test's second goal comes while this one runs, however slow)
                self._first = False
                deadline = time.monotonic() + 60.0
                while not self._goal_queue and time.monotonic() < deadline:
                    time.sleep(0.02)
            sequence = [0, 1]
            for i in range(1, goal_handle.request.order):
                sequence.append(sequence[i] + sequence[i - 1])
                time.sleep(0.1)
            goal_handle.succeed()
            return Fibonacci.Result(sequence=sequence)
        finally:
            with self._goal_queue_lock:
                try:
                    self._current_goal = self._goal_queue.popleft()
                    self._current_goal.execute()
                except IndexError:
                    self._current_goal = None


def main():
    rclpy.init()
    rclpy.spin(QueueServer(), executor=MultiThreadedExecutor())


if __name__ == '__main__':
    main()
"""
