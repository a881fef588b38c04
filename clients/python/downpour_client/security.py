"""The command-line options of a protected server (docs/operations.md, Security)."""


def add_security_arguments(parser):
    """Adds --token, --tls-ca, --tls-cert and --tls-key to an argparse parser."""
    parser.add_argument("--token", help="bearer token (default: $DOWNPOUR_TOKEN)")
    parser.add_argument("--tls-ca", help="CA certificate (PEM) of a TLS server "
                                         "(default: $DOWNPOUR_TLS_CA)")
    parser.add_argument("--tls-cert", help="this client's certificate (PEM), for mutual TLS")
    parser.add_argument("--tls-key", help="this client's private key (PEM), for mutual TLS")


def security_options(args):
    """DownpourClient keyword arguments from add_security_arguments' options."""
    return {"token": args.token, "tls_ca": args.tls_ca, "tls_cert": args.tls_cert,
            "tls_key": args.tls_key}
