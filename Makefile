# The workspace's entry points. Every target first runs tools/setup, which installs what is
# missing (Debian packages, .venv, catkin build) and skips what is already there.
.PHONY: setup demo test bench lint clean

setup:
	@tools/setup

demo: setup
	@tools/demo $(ROBOT)

test: setup
	@tools/run-tests

bench: setup
	@tools/bench

lint: setup
	@. .venv/bin/activate && ruff check src tests bench && ruff format --check src tests bench

clean:
	rm -rf build devel .venv
