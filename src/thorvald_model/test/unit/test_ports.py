"""The port for a private ROS master: free, and outside the range the kernel hands to nodes."""

import random
import socket

from thorvald_model.ports import LOWEST, ephemeral_range, free_port, is_free


def test_the_port_is_free_and_outside_the_ephemeral_range():
    low, high = ephemeral_range()
    for _ in range(20):
        port = free_port()
        assert not low <= port <= high
        assert port >= LOWEST and port != 11311
        assert is_free(port)


def test_a_port_someone_listens_on_is_not_free():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        assert not is_free(s.getsockname()[1])


def test_taken_ports_are_skipped():
    low, _ = ephemeral_range()
    first = free_port(random.Random(7))
    with socket.socket() as s:
        s.bind(("", first))
        s.listen()
        second = free_port(random.Random(7))  # the same draws: the first is taken now
    assert second != first and second < low


def test_an_unreadable_range_file_gives_linux_default(tmp_path):
    assert ephemeral_range(str(tmp_path / "missing")) == (32768, 60999)
    odd = tmp_path / "range"
    odd.write_text("1024\t65000\n")
    assert ephemeral_range(str(odd)) == (1024, 65000)
