# Entry points: `make demo`, `make test`, `make bench`. Each runs tools/setup first.
CARGO ?= cargo

.PHONY: setup build demo test bench lint fuzz ltc-tables install

# Where `make install` puts weft: PREFIX/bin/weft, PREFIX/share/weft/{graphs,shaders}.
PREFIX ?= /usr/local

setup:
	@bash tools/setup

build: setup
	$(CARGO) build --release -p weft-cli

install: build
	@bash tools/install "$(PREFIX)" target/release/weft

demo: build
	@mkdir -p out
	./target/release/weft render scenes/demo.scene --graph graphs/forward.ron --out out/demo.png

lint: setup
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings
	python3 tools/line_limit.py 600
	python3 tools/module_cycles.py

test: lint
	$(CARGO) test --workspace

# Long fuzzing runs (docs/fuzzing.md): the parser properties with FUZZ_CASES cases
# each and MUTANTS graph/shader mutants rendered with validation.
FUZZ_CASES ?= 20000
MUTANTS ?= 2000
fuzz: setup
	WEFT_FUZZ_CASES=$(FUZZ_CASES) $(CARGO) test -p weft-scene --test scene -- --nocapture fuzz::
	WEFT_FUZZ_CASES=$(FUZZ_CASES) $(CARGO) test -p weft-graph --test graph -- --nocapture fuzz::
	WEFT_MUTANTS=$(MUTANTS) $(CARGO) test -p weft-tests --test e2e -- --nocapture mutants::

bench: setup
	$(CARGO) bench --workspace

# Refit the area lights' LTC tables (engine/ltc/tables/ltc_tables.txt; docs/lights.md).
ltc-tables: setup
	$(CARGO) run -p weft-ltc --release --bin ltc-fit
