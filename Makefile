# Entry points: `make demo`, `make test`, `make bench`. Each runs tools/setup first.
CARGO ?= cargo

.PHONY: setup build demo test bench lint

setup:
	@bash tools/setup

build: setup
	$(CARGO) build --release -p weft-cli

demo: build
	@mkdir -p out
	./target/release/weft render scenes/demo.scene --graph graphs/forward.ron --out out/demo.png

lint: setup
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings

test: lint
	$(CARGO) test --workspace

bench: setup
	$(CARGO) bench --workspace
