# covplan-server image: build on Debian 12 with the distribution's packages,
# run the server from a slim runtime stage.
#   docker build -t covplan-server .
#   docker run -p 50051:50051 -p 9464:9464 -v covplan-data:/data covplan-server
FROM debian:12 AS build
ENV DEBIAN_FRONTEND=noninteractive
RUN apt-get update && apt-get install -y --no-install-recommends \
      build-essential cmake ninja-build pkg-config git ca-certificates \
      libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler \
      libabsl-dev libglpk-dev libeigen3-dev libboost-graph-dev libyaml-cpp-dev \
      libpng-dev libgtest-dev libgmock-dev prometheus-cpp-dev libssl-dev \
    && rm -rf /var/lib/apt/lists/*
WORKDIR /src
COPY . .
RUN cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DCOVPLAN_BUILD_TESTS=OFF -DCOVPLAN_BUILD_BENCHMARKS=OFF \
    && cmake --build build --target covplan-server covplan

FROM debian:12-slim
ENV DEBIAN_FRONTEND=noninteractive
# Runtime libraries only (what `ldd covplan-server` resolves to on Debian 12).
RUN apt-get update && apt-get install -y --no-install-recommends \
      libgrpc++1.51 libgrpc29 libprotobuf32 libabsl20220623 libglpk40 libyaml-cpp0.7 \
      libpng16-16 libprometheus-cpp-core1.0 libprometheus-cpp-pull1.0 libcivetweb1 \
      libssl3 libc-ares2 libre2-9 zlib1g ca-certificates \
    && rm -rf /var/lib/apt/lists/* \
    && useradd --system --home /data covplan && mkdir -p /data && chown covplan /data
COPY --from=build /src/build/bin/covplan-server /src/build/bin/covplan /usr/local/bin/
COPY --from=build /src/maps /usr/share/covplan/maps
USER covplan
WORKDIR /data
EXPOSE 50051 9464
STOPSIGNAL SIGTERM
ENTRYPOINT ["/usr/local/bin/covplan-server"]
CMD ["--address=0.0.0.0", "--port=50051", "--metrics_address=0.0.0.0", "--metrics_port=9464", \
     "--store_dir=/data/maps", "--drain_notice_s=1", "--drain_grace_s=10"]
