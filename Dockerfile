# covplan image: build on Debian 12 with the project's own install script,
# run on a slim Debian 12 as a non-root user. The final stage holds the two
# binaries (covplan-server, covplan) and their runtime libraries only.
#
#   scripts/deploy/container_test.sh       # no daemon: buildah + debootstrap'ed bases
#   docker build -t covplan-server .       # with a registry: debian:12 / debian:12-slim
#   docker run -p 50051:50051 -p 9464:9464 covplan-server
#
# BASE / RUNTIME_BASE name the two base images; scripts/deploy/container_test.sh
# passes local images made by debootstrap (there is no registry here).
ARG BASE=docker.io/library/debian:12
ARG RUNTIME_BASE=docker.io/library/debian:12-slim

FROM ${BASE} AS build
ENV DEBIAN_FRONTEND=noninteractive
WORKDIR /src
# The install script first, so the package layer is cached across edits.
COPY scripts/install-deps.sh scripts/install-deps.sh
RUN COVPLAN_MINIMAL=1 bash scripts/install-deps.sh && rm -rf /var/lib/apt/lists/*
COPY . .
RUN cmake -S . -B /build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCOVPLAN_BUILD_SERVER=ON \
      -DCOVPLAN_BUILD_TESTS=OFF -DCOVPLAN_BUILD_BENCHMARKS=OFF \
    && cmake --build /build -j"$(nproc)" --target covplan-server covplan \
    && strip /build/bin/covplan-server /build/bin/covplan

FROM ${RUNTIME_BASE}
ENV DEBIAN_FRONTEND=noninteractive
# Runtime libraries only: what `ldd` resolves the two binaries to on Debian 12.
RUN apt-get update && apt-get install -y --no-install-recommends \
      libgrpc++1.51 libgrpc29 libprotobuf32 libabsl20220623 libglpk40 libyaml-cpp0.7 \
      libpng16-16 libprometheus-cpp-core1.0 libprometheus-cpp-pull1.0 libcivetweb1 \
      libpq5 libssl3 libc-ares2 libre2-9 zlib1g libproj25 \
    && rm -rf /var/lib/apt/lists/* /var/cache/apt/* /usr/share/doc/* /usr/share/man/* \
    && useradd --system --uid 10001 --user-group --home-dir /data --no-create-home covplan \
    && mkdir -p /data && chown covplan:covplan /data
COPY --from=build /build/bin/covplan-server /build/bin/covplan /usr/local/bin/
USER 10001:10001
WORKDIR /data
EXPOSE 50051 9464
STOPSIGNAL SIGTERM
HEALTHCHECK --interval=10s --timeout=3s --start-period=5s --retries=3 \
  CMD ["/usr/local/bin/covplan", "health", "--server", "127.0.0.1:50051", "--timeout-ms", "2000"]
ENTRYPOINT ["/usr/local/bin/covplan-server"]
CMD ["--address=0.0.0.0", "--port=50051", "--metrics_address=0.0.0.0", "--metrics_port=9464", \
     "--store_dir=/data/maps", "--drain_notice_s=1", "--drain_grace_s=10"]
