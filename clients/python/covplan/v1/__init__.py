"""covplan.v1: the raw gRPC stubs, generated from proto/covplan/v1/covplan.proto when the
package is built (covplan_pb2: the messages, covplan_pb2_grpc: CoveragePlannerStub).
The proto's comments document every field."""
